/* The static HTTP/1.0 server behind `lftool serve` (lf_web.h): 127.0.0.1
 * only, GET and HEAD, one request at a time, files inside the root only. */
#include <arpa/inet.h>
#include <errno.h>
#include <limits.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include "lf_web.h"

struct lf_web_server {
    int fd;
    int port;
    char root[PATH_MAX];
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
    s->fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    int one = 1;
    struct sockaddr_in addr = {0};
    addr.sin_family = AF_INET;
    addr.sin_port = htons((uint16_t)port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK); /* never reachable from other machines */
    socklen_t alen = sizeof addr;
    if (s->fd < 0 || setsockopt(s->fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) ||
        bind(s->fd, (struct sockaddr *)&addr, sizeof addr) || listen(s->fd, 16) ||
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

void lf_web_server_close(lf_web_server *s)
{
    if (!s)
        return;
    close(s->fd);
    free(s);
}

static int reply(int fd, const char *status, const char *type, long length)
{
    char hdr[512];
    int n = snprintf(hdr, sizeof hdr,
                     "HTTP/1.0 %s\r\nContent-Type: %s\r\nContent-Length: %ld\r\nCache-Control: no-cache\r\n"
                     "X-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n",
                     status, type, length);
    return send(fd, hdr, (size_t)n, MSG_NOSIGNAL) < 0 ? -1 : 0;
}

static void reply_error(int fd, const char *status)
{
    if (!reply(fd, status, "text/plain", (long)strlen(status) + 1)) {
        send(fd, status, strlen(status), MSG_NOSIGNAL);
        send(fd, "\n", 1, MSG_NOSIGNAL);
    }
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

/* Answers one request on fd. */
static void answer(int fd, const char *root)
{
    char req[8192];
    size_t got = 0;
    while (got < sizeof req - 1) {
        ssize_t r = recv(fd, req + got, sizeof req - 1 - got, 0);
        if (r <= 0)
            break;
        got += (size_t)r;
        req[got] = '\0';
        if (strstr(req, "\r\n\r\n") || strstr(req, "\n\n"))
            break;
    }
    req[got] = '\0';
    char method[8], target[4096], rel[4096], full[PATH_MAX * 2], real[PATH_MAX];
    if (sscanf(req, "%7s %4095s", method, target) != 2) {
        reply_error(fd, "400 Bad Request");
        return;
    }
    int head = !strcmp(method, "HEAD");
    if (!head && strcmp(method, "GET")) {
        reply_error(fd, "405 Method Not Allowed");
        return;
    }
    if (lf_web_clean_path(target, rel, sizeof rel)) {
        reply_error(fd, "403 Forbidden");
        return;
    }
    snprintf(full, sizeof full, "%s%s%s", root, rel, rel[strlen(rel) - 1] == '/' ? "index.html" : "");
    /* the resolved file must lie inside the root (no symlink escapes either) */
    size_t rootlen = strlen(root);
    if (!realpath(full, real)) {
        reply_error(fd, "404 Not Found");
        return;
    }
    if (strncmp(real, root, rootlen) || real[rootlen] != '/') {
        reply_error(fd, "403 Forbidden");
        return;
    }
    FILE *f = fopen(real, "rb");
    struct stat st;
    if (!f || fstat(fileno(f), &st) || !S_ISREG(st.st_mode)) {
        if (f)
            fclose(f);
        reply_error(fd, "404 Not Found");
        return;
    }
    int failed = reply(fd, "200 OK", lf_web_content_type(real), (long)st.st_size);
    char buf[65536];
    size_t n;
    while (!head && !failed && (n = fread(buf, 1, sizeof buf, f)) > 0)
        if (send(fd, buf, n, MSG_NOSIGNAL) < 0)
            break;
    fclose(f);
}

int lf_web_server_serve_one(lf_web_server *s, lf_error *err)
{
    int c = accept(s->fd, NULL, NULL);
    if (c < 0) {
        if (errno == EINTR)
            return LF_ERR_INTERRUPTED;
        if (errno == ECONNABORTED)
            return LF_OK;
        return lf_error_set(err, LF_ERR_IO, "accept: %s", strerror(errno));
    }
    struct timeval tv = {5, 0}; /* a silent client cannot hold the server */
    setsockopt(c, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    setsockopt(c, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    answer(c, s->root);
    close(c);
    return LF_OK;
}

int lf_web_server_run(lf_web_server *s, const volatile sig_atomic_t *stop, lf_error *err)
{
    int rc = LF_OK;
    while (!*stop && (rc == LF_OK || rc == LF_ERR_INTERRUPTED))
        rc = lf_web_server_serve_one(s, err);
    return rc == LF_ERR_INTERRUPTED ? LF_OK : rc;
}
