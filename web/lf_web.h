/* lf_web.h - living pictures: a light field exported as a web page, and the
 * small static HTTP server that shows one over http:// (lftool export-web
 * and lftool serve are thin CLIs over this; docs/web.md).
 *
 *   lf_web_export_opts o = lf_web_export_defaults();
 *   lf_web_export_info info; lf_error err = {0};
 *   if (lf_web_export(&lf, "out/web", &o, &info, &err)) ... err.msg ...
 *
 *   lf_web_server *s;
 *   if (lf_web_server_open("out/web", 8000, &s, &err) == 0) {
 *       lf_web_server_run(s, &stop, &err);   // until a signal handler sets stop
 *       lf_web_server_close(s);
 *   }
 *
 * The page's hand-written files (index.html, lf.js) live in web/ of the
 * source tree; lf_web_find_assets() finds them ($LF_WEB_DIR, the source
 * tree, or next to an installed binary).
 */
#ifndef LF_WEB_H
#define LF_WEB_H

#include <signal.h>

#include <stddef.h>

#include "base/lf_error.h"
#include "lightfield/lf_lightfield.h"

/* Atlases stay within 4096 px a side: the texture size every WebGL 2
 * implementation in use supports (the spec's minimum is 2048). */
#define LF_WEB_MAX_TEXTURE 4096

typedef struct lf_web_export_opts {
    const char *assets_dir; /* web/ holding index.html and lf.js; NULL: lf_web_find_assets() */
    const char *format;     /* "jpg" (default) or "png": the view and focal-stack atlases */
    const char *source;     /* the input's name, shown by the page */
    int stack_slices;       /* focal-stack slices, 2..64 (default 9): the page's fallback without WebGL 2 */
    int have_range;         /* use focus_min..focus_max (px/view) instead of estimating it */
    double focus_min, focus_max;
    int threads;            /* 0: all cores */
} lf_web_export_opts;

typedef struct lf_web_export_info {
    double focus_min, focus_max; /* the disparity range the page refocuses over (px/view) */
    int atlases;                 /* view atlases written */
    long page_bytes;             /* data.js + index.html + lf.js */
} lf_web_export_info;

lf_web_export_opts lf_web_export_defaults(void);

/* Writes out_dir/{index.html, lf.js, data.js} (the directory is created if
 * needed; every file is written atomically).  Fails with a message for
 * views larger than LF_WEB_MAX_TEXTURE, a bad range or slice count, missing
 * assets or an unwritable directory. */
int lf_web_export(const lf_lightfield *lf, const char *out_dir, const lf_web_export_opts *o,
                  lf_web_export_info *info, lf_error *err);

/* The focus range of a picture: the 2nd..98th percentile of the per-pixel
 * disparities dm (estimated over [d0, d1] in n steps), padded by one step
 * and at least two steps wide. */
void lf_web_focus_range(const float *dm, size_t count, double d0, double d1, int n, double *q0, double *q1);

/* Finds the page's asset directory.  0, or an error naming $LF_WEB_DIR. */
int lf_web_find_assets(char *dir, size_t n, lf_error *err);

/* Base64 of n bytes (RFC 4648, with padding), appended to *out as text. */
struct lf_strbuf;
int lf_web_base64(struct lf_strbuf *out, const unsigned char *data, size_t n);

/* ---- the static server: 127.0.0.1 only, GET and HEAD, files inside the
 * root only (no "..", no symlink escapes, regular files only), many clients
 * at once on one thread; its limits (docs/testing.md says why these): ---- */
enum {
    LF_WEB_MAX_CONNECTIONS = 64, /* open client connections; past it the oldest still sending its request goes */
    LF_WEB_REQUEST_MS = 5000,    /* from connect to the end of the request header */
    LF_WEB_STALL_MS = 10000,     /* an answer that makes no progress this long is cut */
    LF_WEB_ANSWER_MS = 300000    /* and no answer takes longer than this */
};
typedef struct lf_web_server lf_web_server;

/* Listens on 127.0.0.1:port (0: any free port) serving files under root. */
int lf_web_server_open(const char *root, int port, lf_web_server **server, lf_error *err);
int lf_web_server_port(const lf_web_server *server);
const char *lf_web_server_root(const lf_web_server *server);
/* Client connections open now (not safe while another thread polls). */
int lf_web_server_connections(const lf_web_server *server);
/* One round: waits up to timeout_ms (-1: until something happens) for
 * connections and socket readiness, accepts, reads, writes, and closes the
 * connections that are done or past their deadline.  0; LF_ERR_INTERRUPTED
 * when a signal interrupted the wait; another code when accepting failed. */
int lf_web_server_poll(lf_web_server *server, int timeout_ms, lf_error *err);
/* Runs rounds until one more request has been answered (tests). */
int lf_web_server_serve_one(lf_web_server *server, lf_error *err);
/* Serves until *stop becomes non-zero (set by the caller's signal handler;
 * checked at least every 250 ms).  0 when stopped, else the code of the
 * failure to accept. */
int lf_web_server_run(lf_web_server *server, const volatile sig_atomic_t *stop, lf_error *err);
void lf_web_server_close(lf_web_server *server);

/* The request path after %XX decoding, query and fragment cut; -1 for NUL,
 * a backslash, a ".." segment, a bad escape or a path not starting with '/'. */
int lf_web_clean_path(const char *raw, char *out, size_t n);
/* The Content-Type the server sends for a file name. */
const char *lf_web_content_type(const char *path);

#endif
