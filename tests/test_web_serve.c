/* test_web_serve.c - the static server under hostile clients (issue 32,
 * point 4), over real loopback sockets: idle connections (more of them than
 * the server has slots), a client that sends its request a byte at a time, a
 * client that asks for a large file and never reads it, and a FIFO in the
 * served folder.  While all of them are connected, a normal client must be
 * answered within 1 s (before the fix it waited 5 s per idle connection
 * ahead of it), and each hostile connection must be closed by its own
 * deadline (web/lf_web.h), not held for ever.  Loopback only; the hostile
 * clients are bounded in count (LF_WEB_MAX_CONNECTIONS + 6) and time (the
 * whole test takes about LF_WEB_STALL_MS). */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "lf_test.h"
#include "web/lf_web.h"

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int connect_to(int port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {0};
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd >= 0 && connect(fd, (struct sockaddr *)&a, sizeof a)) {
        close(fd);
        return -1;
    }
    return fd;
}

/* Sends a whole request and reads the answer; its status line in status. */
static double ask(int port, const char *request, char *status, size_t n)
{
    double t0 = now_s();
    status[0] = '\0';
    int fd = connect_to(port);
    if (fd < 0)
        return -1;
    send(fd, request, strlen(request), MSG_NOSIGNAL);
    char buf[4096];
    size_t got = 0;
    ssize_t r;
    while ((r = recv(fd, buf + got, sizeof buf - 1 - got, 0)) > 0 && got + (size_t)r < sizeof buf - 1)
        got += (size_t)r;
    buf[got] = '\0';
    close(fd);
    char *eol = strstr(buf, "\r\n");
    if (eol)
        *eol = '\0';
    snprintf(status, n, "%.200s", buf);
    return now_s() - t0;
}

/* Whether the server has closed fd (recv gives 0 or a reset) within
 * seconds; the data it sent first is skipped. */
static int closed_within(int fd, double seconds)
{
    double end = now_s() + seconds;
    char buf[65536];
    while (now_s() < end) {
        struct pollfd p = {fd, POLLIN, 0};
        if (poll(&p, 1, 100) > 0) {
            ssize_t r = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
            if (r == 0 || (r < 0 && errno != EAGAIN && errno != EWOULDBLOCK))
                return 1;
        }
    }
    return 0;
}

typedef struct server_run {
    lf_web_server *s;
    volatile sig_atomic_t stop;
    int rc;
} server_run;

static void *serve(void *arg)
{
    server_run *r = arg;
    lf_error err = {0};
    r->rc = lf_web_server_run(r->s, &r->stop, &err);
    return NULL;
}

/* A client that sends "GET / HTTP/1.0\r\n\r\n" one byte every 300 ms. */
static void *dripper(void *arg)
{
    int fd = *(int *)arg;
    const char *req = "GET / HTTP/1.0\r\n\r\n";
    for (size_t i = 0; req[i]; i++) {
        if (send(fd, req + i, 1, MSG_NOSIGNAL) < 0)
            break;
        usleep(300000);
    }
    return NULL;
}

int main(void)
{
    char dir[] = "/tmp/lf_serve_XXXXXX", cmd[1024], path[600];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(cmd, sizeof cmd,
             "printf '<p>hi</p>' > %s/index.html && head -c 33554432 /dev/zero > %s/big.bin && mkfifo %s/fifo.js", dir,
             dir, dir);
    CHECK(system(cmd) == 0);

    lf_error err = {0};
    server_run run = {0};
    CHECK_MSG(lf_web_server_open(dir, 0, &run.s, &err) == 0, "%s", err.msg);
    if (!run.s)
        return lf_test_end();
    int port = lf_web_server_port(run.s);
    pthread_t th;
    pthread_create(&th, NULL, serve, &run);
    char status[256];

    /* more idle connections than the server has slots */
    enum { IDLE = LF_WEB_MAX_CONNECTIONS + 6 };
    int idle[IDLE];
    for (int i = 0; i < IDLE; i++)
        idle[i] = connect_to(port);
    /* a slow request, a byte every 300 ms */
    int slow = connect_to(port);
    pthread_t drip;
    pthread_create(&drip, NULL, dripper, &slow);
    /* a client that asks for 32 MB and reads nothing (a small receive
     * buffer, so the server's sends stop making progress) */
    int deaf = socket(AF_INET, SOCK_STREAM, 0);
    int small = 4096;
    setsockopt(deaf, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
    struct sockaddr_in a = {0};
    a.sin_family = AF_INET, a.sin_port = htons((uint16_t)port), a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    CHECK(connect(deaf, (struct sockaddr *)&a, sizeof a) == 0);
    const char *bigreq = "GET /big.bin HTTP/1.0\r\n\r\n";
    send(deaf, bigreq, strlen(bigreq), MSG_NOSIGNAL);
    usleep(200000);

    /* a FIFO in the folder is not served (and does not block the server) */
    double tf = ask(port, "GET /fifo.js HTTP/1.0\r\n\r\n", status, sizeof status);
    CHECK_MSG(tf >= 0 && tf < 1.0 && strstr(status, "404"), "FIFO: '%s' after %.2f s", status, tf);
    /* the normal client is served within 1 s, all the hostile ones connected */
    double tn = ask(port, "GET /index.html HTTP/1.0\r\n\r\n", status, sizeof status);
    CHECK_MSG(tn >= 0 && tn < 1.0 && !strcmp(status, "HTTP/1.0 200 OK"), "normal client: '%s' after %.2f s", status,
              tn);
    double th2 = ask(port, "HEAD /big.bin HTTP/1.0\r\n\r\n", status, sizeof status);
    CHECK_MSG(th2 >= 0 && th2 < 1.0 && !strcmp(status, "HTTP/1.0 200 OK"), "second client: '%s' after %.2f s",
              status, th2);

    /* the oldest idle connections were dropped to make room, the newest
     * are closed at their request deadline */
    int dropped = 0;
    for (int i = 0; i < 6; i++)
        dropped += closed_within(idle[i], 0.2);
    CHECK_MSG(dropped == 6, "%d of the 6 oldest idle connections were dropped for newer ones", dropped);
    CHECK(closed_within(idle[IDLE - 1], LF_WEB_REQUEST_MS / 1000.0 + 2.0));
    /* the dripping client never completes its request in time */
    CHECK(closed_within(slow, 2.0));
    pthread_join(drip, NULL);
    /* the server still answers */
    tn = ask(port, "GET / HTTP/1.0\r\n\r\n", status, sizeof status);
    CHECK_MSG(tn >= 0 && tn < 1.0 && !strcmp(status, "HTTP/1.0 200 OK"), "after: '%s' after %.2f s", status, tn);
    /* the deaf client is cut once its answer stops moving (it cannot see
     * the close without reading, so the server's count says it) */
    usleep((useconds_t)(LF_WEB_STALL_MS + 1500) * 1000u);
    run.stop = 1; /* seen within 250 ms */
    pthread_join(th, NULL);
    CHECK(run.rc == 0);
    CHECK_MSG(lf_web_server_connections(run.s) == 0, "%d connections still open past every deadline",
              lf_web_server_connections(run.s));
    for (int i = 0; i < IDLE; i++)
        close(idle[i]);
    close(slow), close(deaf);
    lf_web_server_close(run.s);
    snprintf(path, sizeof path, "rm -rf %s", dir);
    CHECK(system(path) == 0);
    return lf_test_end();
}
