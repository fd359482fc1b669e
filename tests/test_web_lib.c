/* test_web_lib.c - the web library directly (web/lf_web.h): base64, the
 * focus range, the export's files and their data, and the static server's
 * answers over a real loopback socket. */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/lf_buf.h"
#include "lf_test.h"
#include "web/lf_web.h"

static int b64_is(const char *in, size_t n, const char *want)
{
    lf_strbuf b = {0};
    lf_web_base64(&b, (const unsigned char *)in, n);
    int ok = b.s ? !strcmp(b.s, want) : want[0] == '\0';
    lf_strbuf_free(&b);
    return ok;
}

static char *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    lf_strbuf b = {0};
    char buf[4096];
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0)
        lf_strbuf_append(&b, buf, got);
    fclose(f);
    if (len)
        *len = b.len;
    return lf_strbuf_take(&b);
}

/* Decodes the base64 payload of the data: URI starting at p (after the comma). */
static unsigned char *unbase64(const char *p, size_t *n)
{
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t len = strcspn(p, "\"");
    unsigned char *out = malloc(len);
    size_t k = 0;
    unsigned acc = 0;
    int bits = 0;
    for (size_t i = 0; out && i < len && p[i] != '='; i++) {
        const char *c = strchr(b64, p[i]);
        if (!c) {
            free(out);
            return NULL;
        }
        acc = acc << 6 | (unsigned)(c - b64), bits += 6;
        if (bits >= 8)
            out[k++] = (unsigned char)(acc >> (bits - 8)), bits -= 8;
    }
    *n = k;
    return out;
}

/* The server thread answers `requests` connections. */
typedef struct served {
    lf_web_server *s;
    int requests;
} served;

static void *serve_thread(void *arg)
{
    served *sv = arg;
    lf_error err = {0};
    for (int i = 0; i < sv->requests; i++)
        lf_web_server_serve_one(sv->s, &err);
    return NULL;
}

/* Sends a raw request to 127.0.0.1:port and returns the whole answer. */
static char *ask(int port, const char *request)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {0};
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a)) {
        if (fd >= 0)
            close(fd);
        return NULL;
    }
    send(fd, request, strlen(request), 0);
    lf_strbuf b = {0};
    char buf[4096];
    ssize_t got;
    while ((got = recv(fd, buf, sizeof buf, 0)) > 0)
        lf_strbuf_append(&b, buf, (size_t)got);
    close(fd);
    return lf_strbuf_take(&b);
}

int main(void)
{
    /* base64 (RFC 4648's examples) */
    CHECK(b64_is("", 0, ""));
    CHECK(b64_is("f", 1, "Zg=="));
    CHECK(b64_is("fo", 2, "Zm8="));
    CHECK(b64_is("foo", 3, "Zm9v"));
    CHECK(b64_is("foobar", 6, "Zm9vYmFy"));

    /* focus range: half the pixels at 0.5 px/view, half at 2.0, searched
     * over [0, 4] in 25 steps (step 1/6): padded by one step each side */
    enum { NPX = 1000 };
    float dm[NPX];
    for (int i = 0; i < NPX; i++)
        dm[i] = i < NPX / 2 ? 0.5f : 2.0f;
    double q0, q1, step = 4.0 / 24;
    lf_web_focus_range(dm, NPX, 0, 4, 25, &q0, &q1);
    CHECK_NEAR(q0, 0.5 - step, 1e-9);
    CHECK_NEAR(q1, 2.0 + step, 1e-9);

    /* request paths */
    char out[256];
    CHECK(lf_web_clean_path("/a%20b?x=1#f", out, sizeof out) == 0 && !strcmp(out, "/a b"));
    CHECK(lf_web_clean_path("/", out, sizeof out) == 0 && !strcmp(out, "/"));
    CHECK(lf_web_clean_path("/%2e%2e/etc/passwd", out, sizeof out) == -1);
    CHECK(lf_web_clean_path("/a/../b", out, sizeof out) == -1);
    CHECK(lf_web_clean_path("/a/..", out, sizeof out) == -1);
    CHECK(lf_web_clean_path("/a..b", out, sizeof out) == 0);
    CHECK(lf_web_clean_path("relative", out, sizeof out) == -1);
    CHECK(lf_web_clean_path("/%zz", out, sizeof out) == -1);
    CHECK(lf_web_clean_path("/%0", out, sizeof out) == -1);
    CHECK(lf_web_clean_path("/a%00b", out, sizeof out) == -1);
    CHECK(lf_web_clean_path("/a\\b", out, sizeof out) == -1);
    CHECK(!strcmp(lf_web_content_type("x/index.html"), "text/html; charset=utf-8"));
    CHECK(!strcmp(lf_web_content_type("data.js"), "text/javascript; charset=utf-8"));
    CHECK(!strcmp(lf_web_content_type("noext"), "application/octet-stream"));

    /* An export of a 3 x 3 camera array whose views show a textured plane
     * at 1 px/view of disparity. */
    char dir[] = "/tmp/lf_web_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    lf_lightfield lf = {0};
    lf_error err = {0};
    CHECK(lf_lightfield_alloc(&lf, 3, 3, 24, 16, &err) == 0);
    for (int iv = 0; iv < 3; iv++)
        for (int iu = 0; iu < 3; iu++) {
            float *v = lf_lightfield_view(&lf, iu, iv);
            for (int t = 0; t < 16; t++)
                for (int s = 0; s < 24; s++) {
                    int x = s + (iu - 1), y = t + (iv - 1); /* the scene point seen at (s, t) */
                    float g = ((x / 3 + y / 3) & 1) ? 0.8f : 0.1f;
                    for (int c = 0; c < 3; c++)
                        v[((size_t)t * 24 + s) * 3 + c] = g;
                }
        }
    lf.layout.kind = LF_LIGHTFIELD_CAMERA_ARRAY;
    lf.disp_per_inv_m = 2.0; /* 1 px/view at 2 m; the search runs from infinity to 0.5 m (0..4) */
    lf.disp_v_per_u = 1.0;
    lf_web_export_opts o = lf_web_export_defaults();
    o.source = "synthetic\"<name>";
    o.stack_slices = 4;
    o.threads = 1;
    char page[512];
    snprintf(page, sizeof page, "%s/page", dir);
    lf_web_export_info info;
    CHECK_MSG(lf_web_export(&lf, page, &o, &info, &err) == 0, "%s", err.msg);
    CHECK(info.focus_min <= 1.0 && info.focus_max >= 1.0);
    CHECK(info.atlases == 1);
    char path[600];
    snprintf(path, sizeof path, "%s/data.js", page);
    size_t n = 0;
    char *js = read_all(path, &n);
    CHECK(js && (long)n <= info.page_bytes);
    CHECK(js && strstr(js, "\"nu\": 3, \"nv\": 3, \"ns\": 24, \"nt\": 16"));
    CHECK(js && strstr(js, "\"source\": \"synthetic__name>\""));
    const char *jpg = js ? strstr(js, "data:image/jpeg;base64,") : NULL;
    const char *png = js ? strstr(js, "data:image/png;base64,") : NULL;
    CHECK(jpg && png);
    if (jpg && png) {
        size_t nb;
        unsigned char *b = unbase64(strchr(jpg, ',') + 1, &nb);
        CHECK(b && nb > 100 && b[0] == 0xFF && b[1] == 0xD8); /* JPEG SOI */
        free(b);
        b = unbase64(strchr(png, ',') + 1, &nb);
        CHECK(b && nb > 30 && b[0] == 0x89 && b[1] == 'P' && b[2] == 'N' && b[3] == 'G');
        free(b);
    }
    free(js);
    char assets[512];
    CHECK(lf_web_find_assets(assets, sizeof assets, &err) == 0);
    const char *names[2] = {"index.html", "lf.js"};
    for (int i = 0; i < 2; i++) {
        char a[700], b[700];
        snprintf(a, sizeof a, "%s/%s", assets, names[i]);
        snprintf(b, sizeof b, "%s/%s", page, names[i]);
        size_t na, nb;
        char *ta = read_all(a, &na), *tb = read_all(b, &nb);
        CHECK(ta && tb && na == nb && !memcmp(ta, tb, na));
        free(ta);
        free(tb);
    }
    char cmd[700];
    snprintf(cmd, sizeof cmd, "test $(ls -A %s | wc -l) -eq 3", page); /* no temporary files left */
    CHECK(system(cmd) == 0);
    /* refusals */
    o.stack_slices = 1;
    lf_error e1 = {0};
    CHECK(lf_web_export(&lf, page, &o, &info, &e1) != 0 && strstr(e1.msg, "2..64"));
    o.stack_slices = 4, o.format = "gif";
    lf_error e2 = {0};
    CHECK(lf_web_export(&lf, page, &o, &info, &e2) != 0 && strstr(e2.msg, "gif"));
    o.format = "png", o.have_range = 1, o.focus_min = 2, o.focus_max = 1;
    lf_error e3 = {0};
    CHECK(lf_web_export(&lf, page, &o, &info, &e3) != 0 && strstr(e3.msg, "max > min"));
    lf_lightfield_free(&lf);

    /* The server: a page, a file outside the root, four requests. */
    snprintf(path, sizeof path, "%s/secret.txt", dir);
    FILE *f = fopen(path, "w");
    if (f)
        fputs("secret\n", f), fclose(f);
    lf_web_server *srv = NULL;
    CHECK(lf_web_server_open(page, 0, &srv, &err) == 0);
    if (srv) {
        int port = lf_web_server_port(srv);
        CHECK(port > 0);
        served sv = {srv, 5};
        pthread_t th;
        pthread_create(&th, NULL, serve_thread, &sv);
        char *r1 = ask(port, "GET / HTTP/1.0\r\n\r\n");
        CHECK(r1 && !strncmp(r1, "HTTP/1.0 200 OK", 15) && strstr(r1, "text/html") && strstr(r1, "<"));
        char *r2 = ask(port, "GET /../secret.txt HTTP/1.0\r\n\r\n");
        CHECK(r2 && strstr(r2, "403") && !strstr(r2, "secret\n"));
        char *r3 = ask(port, "GET /missing.js HTTP/1.0\r\n\r\n");
        CHECK(r3 && strstr(r3, "404"));
        char *r4 = ask(port, "POST /data.js HTTP/1.0\r\n\r\n");
        CHECK(r4 && strstr(r4, "405"));
        char *r5 = ask(port, "HEAD /data.js HTTP/1.0\r\n\r\n");
        CHECK(r5 && strstr(r5, "200 OK") && strstr(r5, "text/javascript") && strstr(r5, "\r\n\r\n")[4] == '\0');
        pthread_join(th, NULL);
        free(r1), free(r2), free(r3), free(r4), free(r5);
        volatile sig_atomic_t stop = 1; /* already asked to stop: returns without waiting */
        CHECK(lf_web_server_run(srv, &stop, &err) == 0);
        lf_web_server_close(srv);
    }
    lf_web_server *bad = NULL;
    CHECK(lf_web_server_open("/nonexistent/dir", 0, &bad, &err) != 0 && bad == NULL);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return lf_test_end();
}
