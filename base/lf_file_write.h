/* lf_file_write.h - atomic file output, the one way lensfield writes files.
 *
 * Data goes to a hidden temporary file beside the target
 * ("<dir>/.<name>.tmpXXXXXX.<ext>": same filesystem, same extension so a
 * library that picks the format from the name still can), which is
 * fsync'ed and renamed over the target only when complete.  A crash or an
 * error never leaves a half-written file under the target's name.
 *
 *   lf_error err = {0};
 *   if (lf_file_write_atomic("out/page.html", text, strlen(text), &err)) ... err.msg ...
 *
 *   char tmp[PATH_MAX];                   // for writers that need a path
 *   if (lf_file_temp_create(path, tmp, sizeof tmp, &err)) ...;
 *   ... write tmp ...
 *   if (failed) unlink(tmp); else lf_file_temp_commit(tmp, path, &err);
 */
#ifndef LF_FILE_WRITE_H
#define LF_FILE_WRITE_H

#include <stddef.h>

#include "lf_error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Creates an empty temporary file beside `path` and puts its name in tmp. */
int lf_file_temp_create(const char *path, char *tmp, size_t tmp_size, lf_error *err);
/* fsyncs tmp and renames it over path (keeping an existing target's
 * permissions).  On failure tmp is left for the caller to unlink. */
int lf_file_temp_commit(const char *tmp, const char *path, lf_error *err);
/* Writes len bytes to path atomically. */
int lf_file_write_atomic(const char *path, const void *data, size_t len, lf_error *err);

/* Creates the directory dir (its parent must exist); one that exists is fine. */
int lf_dir_create(const char *dir, lf_error *err);
/* Creates the directories leading to the file path (mkdir -p of its folder). */
int lf_dir_create_parents(const char *path, lf_error *err);
/* Before long work: creates path's folder and a probe file beside path
 * (removed again), so an unwritable output fails now, not at the end. */
int lf_file_check_writable(const char *path, lf_error *err);
/* Removes the hidden temporaries lf_file_temp_create made for path that a
 * killed process left behind ("<dir>/.<name>.tmpXXXXXX.<ext>"); returns how
 * many.  For a program about to write path itself (nothing else may be
 * writing it then). */
int lf_file_temp_clean(const char *path);
/* A folder output built beside its target and moved into place, so a failed
 * or killed run never leaves a half-written folder (issue 32):
 * lf_dir_stage_begin creates "<parent>/.<name>.stageXXXXXX" for dir (after
 * removing such staging folders a killed run left for the same dir) and puts
 * its path in stage; the writer puts its files there (flat, no
 * sub-folders); lf_dir_stage_commit moves them into dir: a rename of the
 * whole folder when dir does not exist, else one rename per file (files of
 * dir that this run did not write are kept); lf_dir_stage_abort removes the
 * staging folder and what is in it. */
int lf_dir_stage_begin(const char *dir, char *stage, size_t stage_size, lf_error *err);
int lf_dir_stage_commit(const char *stage, const char *dir, lf_error *err);
void lf_dir_stage_abort(const char *stage);
/* Before reading: LF_ERR_PARAM when output names one of the n inputs (the
 * same path, or the same file through another name: device and inode),
 * since writing it would destroy what is being read.  NULL entries are
 * skipped. */
int lf_output_is_input(const char *output, const char *const *inputs, int n, lf_error *err);

#ifdef __cplusplus
}
#endif
#endif
