/* lf_file.h - file reads that transparently gunzip, whole or as a stream.
 *
 * Every file a scene names (the scene itself, Include/Import, PLY meshes,
 * spectrum files, lens prescriptions) may be gzip-compressed, as pbrt-v4
 * allows.  Compression is recognised by the gzip magic bytes 1f 8b, never by
 * the file name, so "mesh.ply" holding gzip data and "mesh.ply.gz" holding
 * plain text both work.  Concatenated gzip members are read as one stream
 * (as gunzip does).  Decompression uses zlib.
 *
 *   char *data; size_t len; lf_error err = {0};
 *   if (lf_file_read("scene.pbrt.gz", LF_FILE_MAX_DEFAULT, &data, &len, &err))
 *       ... err.msg names the file and what went wrong ...
 *   ... data[len] == '\0' ...
 *   free(data);
 */
#ifndef LF_FILE_H
#define LF_FILE_H

#include <stddef.h>

#include "lf_error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Default limit on the (decompressed) size: 4 GiB. */
#define LF_FILE_MAX_DEFAULT ((size_t)4 << 30)

/* Reads the whole file at `path`, gunzipping it if it starts with the gzip
 * magic.  On success *data is a malloc'ed buffer of *len bytes followed by a
 * NUL (not counted), *was_gzip (if not NULL) says whether it was compressed,
 * and 0 is returned.  A file (or decompressed stream) longer than max_bytes
 * fails with LF_ERR_IO and a message giving the limit; corrupt or truncated
 * gzip data fails with LF_ERR_PARSE naming the file.  Messages start with the
 * path.  *data is NULL on failure. */
int lf_file_read(const char *path, size_t max_bytes, char **data, size_t *len, int *was_gzip, lf_error *err);
/* The first max_bytes (at most) of the file's content, gunzipped as
 * lf_file_read does, without inflating the rest: a format's header read
 * before the whole file, so the sizes it declares can bound the full read
 * (NUL-terminated; *len may be less than max_bytes). */
int lf_file_read_head(const char *path, size_t max_bytes, char **data, size_t *len, int *was_gzip, lf_error *err);

/* Gunzips an in-memory buffer (which must start with the gzip magic) into a
 * malloc'ed, NUL-terminated buffer.  `name` is used in messages. */
int lf_gunzip(const unsigned char *in, size_t in_len, const char *name, size_t max_bytes, char **data, size_t *len,
              lf_error *err);

/* A stream of the same content, a chunk at a time, for readers whose memory
 * should follow what they keep rather than the file's size (the scene
 * parser: a 3 GB comment line costs it nothing).  Opening reads ahead
 * 64 KiB to see the gzip magic; open errors are lf_file_read's; reads fail
 * with its messages for corrupt, truncated or trailing gzip data.
 *
 *   lf_file_stream *s; char buf[4096]; size_t got;
 *   if (lf_file_stream_open(path, &s, &err)) ...
 *   while (!(rc = lf_file_stream_read(s, buf, sizeof buf, &got, &err)) && got) ...
 *   lf_file_stream_close(s);
 */
typedef struct lf_file_stream lf_file_stream;
int lf_file_stream_open(const char *path, lf_file_stream **out, lf_error *err);
/* Up to n bytes of content; *got < n only at the end (0: nothing left). */
int lf_file_stream_read(lf_file_stream *s, char *buf, size_t n, size_t *got, lf_error *err);
int lf_file_stream_was_gzip(const lf_file_stream *s);
/* Accepts NULL. */
void lf_file_stream_close(lf_file_stream *s);

/* 1 if the buffer starts with the gzip magic bytes 1f 8b. */
int lf_is_gzip(const void *buf, size_t len);
/* 1 when path ends in ext (".exr"), ignoring case. */
int lf_path_has_ext(const char *path, const char *ext);

#ifdef __cplusplus
}
#endif
#endif
