/* The static HTTP/1.0 server behind `lftool serve` (lf_web.h): 127.0.0.1
 * only, GET and HEAD, files inside the root only.
 *
 * One thread, one poll() loop, every socket non-blocking, so no client can
 * stall another (issue 32): a client that sends its request slowly, sends
 * nothing, or does not read its answer holds one of LF_WEB_MAX_CONNECTIONS
 * slots until its own deadline, while the others are served.  The limits
 * (lf_web.h) and why each has its value are in docs/testing.md. */
#define _GNU_SOURCE /* accept4 */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <stdint.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "lf_web.h"

enum { REQ_MAX = 8192, CHUNK = 65536 };

/* One client connection: reading its request, then writing the answer. */
typedef struct conn {
    int fd;
    int file;        /* the file being sent, or -1 */
    int writing;     /* 0 while the request is read */
    size_t got;      /* request bytes read */
    size_t len, off; /* bytes in out[], bytes of them sent */
    int64_t accepted_ms, progress_ms;
    uint64_t order; /* accept order: times tie within one poll round */
    char req[REQ_MAX];
    char out[CHUNK];
} conn;

struct lf_web_server {
    int fd;
    int port;
    char root[PATH_MAX];
    conn *conns[LF_WEB_MAX_CONNECTIONS];
    long answered;     /* requests answered so far */
    uint64_t accepted; /* connections accepted so far */
};

int lf_web_server_open(const char *root, int port, lf_web_server **server, lf_error *err)
{
    *server = NULL;
    if (port < 0 || port > 65535)
        return lf_error_set(err, LF_ERR_PARAM, "port %d is not 0..65535", port);
    lf_web_server *s = calloc(1, sizeof *s);
    if (!s)
        return lf_error_set(err, LF_ERR_NOMEM, "out of memory");
    struct stat st;
    if (!realpath(root, s->root) || stat(s->root, &st) || !S_ISDIR(st.st_mode)) {
        free(s);
        return lf_error_set(err, LF_ERR_IO, "%s is not a directory", root);
    }
    s->fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    int one = 1;
    struct sockaddr_in addr = {0};
    addr.sin_family = AF_INET;
    addr.sin_port = htons((uint16_t)port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK); /* never reachable from other machines */
    socklen_t alen = sizeof addr;
    if (s->fd < 0 || setsockopt(s->fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) ||
        bind(s->fd, (struct sockaddr *)&addr, sizeof addr) || listen(s->fd, 64) ||
        getsockname(s->fd, (struct sockaddr *)&addr, &alen)) {
        int rc = lf_error_set(err, LF_ERR_IO, "cannot listen on 127.0.0.1:%d: %s", port, strerror(errno));
        if (s->fd >= 0)
            close(s->fd);
        free(s);
        return rc;
    }
    s->port = ntohs(addr.sin_port);
    *server = s;
    return LF_OK;
}

int lf_web_server_port(const lf_web_server *s)
{
    return s->port;
}

const char *lf_web_server_root(const lf_web_server *s)
{
    return s->root;
}

int lf_web_server_connections(const lf_web_server *s)
{
    int n = 0;
    for (int i = 0; i < LF_WEB_MAX_CONNECTIONS; i++)
        n += s->conns[i] != NULL;
    return n;
}

void lf_web_server_close(lf_web_server *s)
{
    if (!s)
        return;
    for (int i = 0; i < LF_WEB_MAX_CONNECTIONS; i++)
        if (s->conns[i]) {
            close(s->conns[i]->fd);
            if (s->conns[i]->file >= 0)
                close(s->conns[i]->file);
            free(s->conns[i]);
        }
    close(s->fd);
    free(s);
}

static int64_t now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* Puts the answer's header into c->out; the body follows from c->file. */
static void reply(conn *c, const char *status, const char *type, long length)
{
    int n = snprintf(c->out, sizeof c->out,
                     "HTTP/1.0 %s\r\nContent-Type: %s\r\nContent-Length: %ld\r\nCache-Control: no-cache\r\n"
                     "X-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n",
                     status, type, length);
    c->len = n > 0 && (size_t)n < sizeof c->out ? (size_t)n : 0, c->off = 0;
}

static void reply_error(conn *c, const char *status)
{
    reply(c, status, "text/plain", (long)strlen(status) + 1);
    int n = snprintf(c->out + c->len, sizeof c->out - c->len, "%s\n", status);
    c->len += n > 0 ? (size_t)n : 0;
}

const char *lf_web_content_type(const char *path)
{
    static const char *const types[][2] = {{".html", "text/html; charset=utf-8"},
                                           {".js", "text/javascript; charset=utf-8"},
                                           {".css", "text/css"},
                                           {".png", "image/png"},
                                           {".jpg", "image/jpeg"},
                                           {".json", "application/json"}};
    const char *dot = strrchr(path, '.');
    for (size_t i = 0; dot && i < sizeof types / sizeof types[0]; i++)
        if (!strcmp(dot, types[i][0]))
            return types[i][1];
    return "application/octet-stream";
}

static int hex_digit(int c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

int lf_web_clean_path(const char *raw, char *out, size_t n)
{
    size_t k = 0;
    for (const char *p = raw; *p && *p != '?' && *p != '#'; p++) {
        int c = (unsigned char)*p;
        if (c == '%') {
            int hi = p[1] ? hex_digit(p[1]) : -1, lo = hi >= 0 && p[2] ? hex_digit(p[2]) : -1;
            if (hi < 0 || lo < 0)
                return -1;
            c = hi * 16 + lo, p += 2;
        }
        if (c == 0 || c == '\\' || k + 1 >= n)
            return -1;
        out[k++] = (char)c;
    }
    out[k] = '\0';
    if (out[0] != '/')
        return -1;
    for (const char *s = out; (s = strstr(s, "..")) != NULL; s += 2)
        if (s[-1] == '/' && (s[2] == '/' || s[2] == '\0'))
            return -1;
    return 0;
}

/* Opens the file a cleaned path names inside root: the fd of a regular
 * file (its resolved path in real), else -1 with *status the answer (404
 * or 403).  O_NONBLOCK so that a
 * FIFO in the folder cannot block the open. */
static int open_inside(const char *root, const char *rel, struct stat *st, char real[PATH_MAX], const char **status)
{
    char full[PATH_MAX * 2];
    snprintf(full, sizeof full, "%s%s%s", root, rel, rel[strlen(rel) - 1] == '/' ? "index.html" : "");
    *status = "404 Not Found";
    if (!realpath(full, real))
        return -1;
    /* the resolved file must lie inside the root (no symlink escapes either) */
    size_t rootlen = strlen(root);
    if (strncmp(real, root, rootlen) || real[rootlen] != '/') {
        *status = "403 Forbidden";
        return -1;
    }
    int fd = open(real, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd >= 0 && (fstat(fd, st) || !S_ISREG(st->st_mode))) {
        close(fd);
        fd = -1;
    }
    return fd;
}

/* The request in c->req is complete: prepares the answer. */
static void answer(conn *c, const char *root)
{
    char method[8], target[4096], rel[4096];
    c->writing = 1;
    if (sscanf(c->req, "%7s %4095s", method, target) != 2) {
        reply_error(c, "400 Bad Request");
        return;
    }
    int head = !strcmp(method, "HEAD");
    if (!head && strcmp(method, "GET")) {
        reply_error(c, "405 Method Not Allowed");
        return;
    }
    if (lf_web_clean_path(target, rel, sizeof rel)) {
        reply_error(c, "403 Forbidden");
        return;
    }
    struct stat st;
    const char *status;
    char real[PATH_MAX];
    int fd = open_inside(root, rel, &st, real, &status);
    if (fd < 0) {
        reply_error(c, status);
        return;
    }
    reply(c, "200 OK", lf_web_content_type(real), (long)st.st_size);
    if (head)
        close(fd);
    else
        c->file = fd;
}

static void drop(lf_web_server *s, int i)
{
    conn *c = s->conns[i];
    close(c->fd);
    if (c->file >= 0)
        close(c->file);
    free(c);
    s->conns[i] = NULL;
}

/* Reads what the client sent; answers once the header is complete. */
static void on_readable(lf_web_server *s, conn *c, int64_t t)
{
    ssize_t r = recv(c->fd, c->req + c->got, sizeof c->req - 1 - c->got, MSG_DONTWAIT);
    if (r == 0 || (r < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
        c->got = sizeof c->req; /* closed before a whole request: drop it */
        return;
    }
    if (r > 0) {
        c->got += (size_t)r, c->progress_ms = t;
        c->req[c->got] = '\0';
    }
    if (strstr(c->req, "\r\n\r\n") || strstr(c->req, "\n\n") || c->got == sizeof c->req - 1)
        answer(c, s->root);
}

/* Sends what the client's socket takes.  1 when the answer is complete or
 * the client has gone, 0 while more remains. */
static int on_writable(conn *c, int64_t t)
{
    for (;;) {
        if (c->off == c->len) {
            ssize_t n = c->file >= 0 ? read(c->file, c->out, sizeof c->out) : 0;
            if (n <= 0)
                return 1;
            c->len = (size_t)n, c->off = 0;
        }
        ssize_t w = send(c->fd, c->out + c->off, c->len - c->off, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (w < 0)
            return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? 0 : 1;
        c->off += (size_t)w, c->progress_ms = t;
    }
}

/* The slot to give a new connection: a free one, else the oldest that is
 * still sending its request (slow or idle clients make room for new ones;
 * answers under way are not cut), else -1. */
static int free_slot(lf_web_server *s)
{
    int oldest = -1;
    for (int i = 0; i < LF_WEB_MAX_CONNECTIONS; i++) {
        if (!s->conns[i])
            return i;
        if (!s->conns[i]->writing && (oldest < 0 || s->conns[i]->order < s->conns[oldest]->order))
            oldest = i;
    }
    if (oldest >= 0)
        drop(s, oldest);
    return oldest;
}

static int accept_all(lf_web_server *s, int64_t t, lf_error *err)
{
    for (;;) {
        int fd = accept4(s->fd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK || errno == ECONNABORTED || errno == EINTR)
                return LF_OK;
            if (errno == EMFILE || errno == ENFILE) /* out of descriptors: serve the ones we have */
                return LF_OK;
            return lf_error_set(err, LF_ERR_IO, "accept: %s", strerror(errno));
        }
        int i = free_slot(s);
        conn *c = i >= 0 ? malloc(sizeof *c) : NULL;
        if (!c) { /* every slot is sending an answer, or no memory: refuse this one */
            static const char busy[] = "HTTP/1.0 503 Service Unavailable\r\nContent-Length: 0\r\n\r\n";
            ssize_t ignored = send(fd, busy, sizeof busy - 1, MSG_NOSIGNAL | MSG_DONTWAIT);
            (void)ignored;
            close(fd);
            continue;
        }
        *c = (conn){.fd = fd, .file = -1, .accepted_ms = t, .progress_ms = t, .order = s->accepted++};
        c->req[0] = '\0';
        s->conns[i] = c;
    }
}

/* Whether a connection has outlived its deadline (lf_web.h's limits). */
static int expired(const conn *c, int64_t t)
{
    if (!c->writing)
        return t - c->accepted_ms > LF_WEB_REQUEST_MS;
    return t - c->progress_ms > LF_WEB_STALL_MS || t - c->accepted_ms > LF_WEB_ANSWER_MS;
}

int lf_web_server_poll(lf_web_server *s, int timeout_ms, lf_error *err)
{
    struct pollfd fds[LF_WEB_MAX_CONNECTIONS + 1];
    int who[LF_WEB_MAX_CONNECTIONS + 1], n = 0;
    fds[n] = (struct pollfd){.fd = s->fd, .events = POLLIN}, who[n++] = -1;
    for (int i = 0; i < LF_WEB_MAX_CONNECTIONS; i++)
        if (s->conns[i])
            fds[n] = (struct pollfd){.fd = s->conns[i]->fd, .events = s->conns[i]->writing ? POLLOUT : POLLIN},
            who[n++] = i;
    /* wake up in time for the nearest deadline */
    int wait = n > 1 && (timeout_ms < 0 || timeout_ms > 250) ? 250 : timeout_ms;
    int ready = poll(fds, (nfds_t)n, wait);
    if (ready < 0)
        return errno == EINTR ? LF_ERR_INTERRUPTED : lf_error_set(err, LF_ERR_IO, "poll: %s", strerror(errno));
    int64_t t = now_ms();
    for (int k = 1; k < n; k++) {
        conn *c = s->conns[who[k]];
        int done = 0, now_writing = 0;
        if (fds[k].revents & (POLLERR | POLLNVAL))
            done = 1;
        else if (!c->writing && (fds[k].revents & (POLLIN | POLLHUP))) {
            on_readable(s, c, t);
            done = !c->writing && c->got >= sizeof c->req - 1;
            now_writing = c->writing; /* try to send at once */
        }
        if (!done && c->writing && (now_writing || fds[k].revents & (POLLOUT | POLLHUP))) {
            done = on_writable(c, t);
            s->answered += done;
        }
        if (done || expired(c, t))
            drop(s, who[k]);
    }
    return fds[0].revents & POLLIN ? accept_all(s, t, err) : LF_OK;
}

int lf_web_server_serve_one(lf_web_server *s, lf_error *err)
{
    long before = s->answered;
    while (s->answered == before) {
        int rc = lf_web_server_poll(s, -1, err);
        if (rc)
            return rc;
    }
    return LF_OK;
}

int lf_web_server_run(lf_web_server *s, const volatile sig_atomic_t *stop, lf_error *err)
{
    int rc = LF_OK;
    while (!*stop && (rc == LF_OK || rc == LF_ERR_INTERRUPTED))
        rc = lf_web_server_poll(s, 250, err);
    return rc == LF_ERR_INTERRUPTED ? LF_OK : rc;
}
