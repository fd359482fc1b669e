/* Atomic file output (lf_file_write.h). */
#include "lf_file_write.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* The extension of a file name without its dot, or "". */
static const char *extension_of(const char *base)
{
    const char *dot = strrchr(base, '.');
    return dot && dot != base ? dot + 1 : "";
}

/* Creates an empty temporary file beside `path`, named
 * "<dir>/.<name>.tmpXXXXXX.<ext>" so it is hidden, cannot collide with the
 * target, and still ends in the real extension (OpenImageIO picks the
 * format from it).  Created with O_EXCL and mode 0666 so the umask, not a
 * hard-coded 0600, decides the final file's permissions. */
int lf_file_temp_create(const char *path, char *tmp, size_t tmp_size, lf_error *err)
{
    static atomic_uint counter;
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    if (!*base)
        return lf_error_set(err, LF_ERR_PARAM, "cannot write '%s': path names a directory", path);
    int dir_len = slash ? (int)(slash - path) : 0;
    const char *ext = extension_of(base);
    static const char alphabet[] = "abcdefghijklmnopqrstuvwxyz0123456789";

    for (int attempt = 0; attempt < 100; attempt++) {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        uint64_t r = ((uint64_t)getpid() << 32) ^ (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 20) ^
                     ((uint64_t)atomic_fetch_add(&counter, 1) * 0x9E3779B97F4A7C15ull);
        r *= 0xBF58476D1CE4E5B9ull; /* splitmix-style scramble */
        r ^= r >> 31;
        char rnd[7];
        for (int i = 0; i < 6; i++, r /= 36)
            rnd[i] = alphabet[r % 36];
        rnd[6] = '\0';
        int n = snprintf(tmp, tmp_size, "%.*s%s.%s.tmp%s%s%s", dir_len, path, slash ? "/" : "", base, rnd,
                         *ext ? "." : "", ext);
        if (n < 0 || (size_t)n >= tmp_size)
            return lf_error_set(err, LF_ERR_PARAM, "cannot write '%s': path too long", path);
        int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) {
            close(fd);
            return LF_OK;
        }
        if (errno == EEXIST)
            continue;
        int e = errno;
        if (e == ENOENT || e == ENOTDIR) {
            char dir[PATH_MAX];
            snprintf(dir, sizeof dir, "%.*s", dir_len, path);
            return lf_error_set(err, LF_ERR_IO, "cannot write '%s': directory '%s' does not exist", path,
                                slash ? dir : ".");
        }
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': cannot create a temporary file beside it: %s",
                            path, strerror(e));
    }
    return lf_error_set(err, LF_ERR_IO, "cannot write '%s': no free temporary file name", path);
}

/* Makes the finished temporary file durable and moves it over the target:
 * fsync before rename, or a crash could leave the new name pointing at
 * unwritten blocks. */
int lf_file_temp_commit(const char *tmp, const char *path, lf_error *err)
{
    int fd = open(tmp, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': temporary file '%s' vanished: %s", path, tmp,
                            strerror(errno));
    struct stat st;
    /* Replacing a file keeps its permissions, as editing it in place would. */
    if (stat(path, &st) == 0 && S_ISREG(st.st_mode))
        fchmod(fd, st.st_mode & 07777);
    if (fsync(fd) != 0) {
        int e = errno;
        close(fd);
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': fsync failed: %s", path, strerror(e));
    }
    close(fd);
    if (rename(tmp, path) != 0)
        return lf_error_set(err, LF_ERR_IO, "cannot write '%s': rename from '%s' failed: %s", path, tmp,
                            strerror(errno));
    /* Persist the directory entry too.  A failure here is not reported: the
     * image is complete and in place, only its durability across a power
     * cut is uncertain. */
    const char *slash = strrchr(path, '/');
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) + 1 : 1, slash ? path : ".");
    int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        fsync(dfd);
        close(dfd);
    }
    return LF_OK;
}

int lf_file_write_atomic(const char *path, const void *data, size_t len, lf_error *err)
{
    char tmp[PATH_MAX];
    int rc = lf_file_temp_create(path, tmp, sizeof tmp, err);
    if (rc)
        return rc;
    int fd = open(tmp, O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0) {
        rc = lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", tmp, strerror(errno));
        unlink(tmp);
        return rc;
    }
    const char *p = data;
    size_t left = len;
    while (left > 0) {
        ssize_t n = write(fd, p, left);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            rc = lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", path, n < 0 ? strerror(errno) : "short write");
            close(fd);
            unlink(tmp);
            return rc;
        }
        p += n;
        left -= (size_t)n;
    }
    if (close(fd) != 0) {
        rc = lf_error_set(err, LF_ERR_IO, "cannot write '%s': %s", path, strerror(errno));
        unlink(tmp);
        return rc;
    }
    rc = lf_file_temp_commit(tmp, path, err);
    if (rc)
        unlink(tmp);
    return rc;
}

int lf_dir_create(const char *dir, lf_error *err)
{
    if (mkdir(dir, 0777) && errno != EEXIST)
        return lf_error_set(err, LF_ERR_IO, "cannot create directory %s: %s", dir, strerror(errno));
    return LF_OK;
}

int lf_dir_create_parents(const char *path, lf_error *err)
{
    char buf[PATH_MAX];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf)
        return lf_error_set(err, LF_ERR_PARAM, "path too long: %s", path);
    char *slash = strrchr(buf, '/');
    if (!slash || slash == buf)
        return LF_OK;
    *slash = '\0';
    for (char *p = buf + 1;; p++)
        if (*p == '/' || !*p) {
            char c = *p;
            *p = '\0';
            if (mkdir(buf, 0777) && errno != EEXIST)
                return lf_error_set(err, LF_ERR_IO, "cannot create the directory of %s: %s", path, strerror(errno));
            if (!c)
                return LF_OK;
            *p = c;
        }
}

int lf_file_check_writable(const char *path, lf_error *err)
{
    if (lf_dir_create_parents(path, err))
        return err ? err->code : LF_ERR_IO;
    char probe[PATH_MAX];
    const char *slash = strrchr(path, '/');
    int dir_len = slash ? (int)(slash - path) : 0;
    snprintf(probe, sizeof probe, "%.*s%s.lensfield-probe-%ld", dir_len, path, slash ? "/" : "", (long)getpid());
    FILE *f = fopen(probe, "wb");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "cannot write %s: %s", path, strerror(errno));
    fclose(f);
    remove(probe);
    return LF_OK;
}

int lf_output_is_input(const char *output, const char *const *inputs, int n, lf_error *err)
{
    if (!output)
        return LF_OK;
    struct stat so;
    int out_exists = stat(output, &so) == 0;
    for (int i = 0; i < n; i++) {
        const char *in = inputs[i];
        if (!in)
            continue;
        struct stat si;
        int same = strcmp(in, output) == 0 ||
                   (out_exists && stat(in, &si) == 0 && si.st_dev == so.st_dev && si.st_ino == so.st_ino);
        if (same)
            return lf_error_set(err, LF_ERR_PARAM, "the output '%s' is the input '%s': writing it would destroy the "
                                "input (choose another output name)", output, in);
    }
    return LF_OK;
}

int lf_file_temp_clean(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *ext = extension_of(base);
    char dir[PATH_MAX], prefix[PATH_MAX];
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) + 1 : 1, slash ? path : ".");
    int pl = snprintf(prefix, sizeof prefix, ".%s.tmp", base);
    if (!*base || pl < 0 || (size_t)pl >= sizeof prefix)
        return 0;
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int removed = 0;
    for (struct dirent *e; (e = readdir(d));) {
        const char *n = e->d_name;
        if (strncmp(n, prefix, (size_t)pl) != 0)
            continue;
        const char *r = n + pl; /* six of [a-z0-9], then ".<ext>" or the end (lf_file_temp_create's names) */
        int ok = 1;
        for (int i = 0; i < 6; i++)
            ok = ok && ((r[i] >= 'a' && r[i] <= 'z') || (r[i] >= '0' && r[i] <= '9'));
        if (!ok || (*ext ? (r[6] != '.' || strcmp(r + 7, ext) != 0) : r[6] != '\0'))
            continue;
        char full[PATH_MAX * 2];
        snprintf(full, sizeof full, "%s/%s", dir, n);
        struct stat st;
        if (lstat(full, &st) == 0 && S_ISREG(st.st_mode) && unlink(full) == 0)
            removed++;
    }
    closedir(d);
    return removed;
}

/* The process's umask, read without changing it (umask() would race with
 * other threads creating files); 022 when /proc cannot tell. */
static mode_t current_umask(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    unsigned m = 022;
    char line[256];
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "Umask: %o", &m) == 1)
            break;
    if (f)
        fclose(f);
    return (mode_t)m;
}

/* Removes the files in the flat folder dir, then dir. */
static void remove_flat_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        char full[PATH_MAX * 2];
        for (struct dirent *e; (e = readdir(d));)
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
                snprintf(full, sizeof full, "%s/%s", dir, e->d_name);
                unlink(full);
            }
        closedir(d);
    }
    rmdir(dir);
}

/* parent folder (with a trailing '/') and base name of dir */
static int split_dir(const char *dir, char *parent, size_t pn, char *base, size_t bn)
{
    char buf[PATH_MAX];
    if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf)
        return -1;
    size_t l = strlen(buf);
    while (l > 1 && buf[l - 1] == '/')
        buf[--l] = '\0';
    char *slash = strrchr(buf, '/');
    snprintf(parent, pn, "%.*s", slash ? (int)(slash - buf) + 1 : 2, slash ? buf : "./");
    snprintf(base, bn, "%s", slash ? slash + 1 : buf);
    return *base && strcmp(base, ".") && strcmp(base, "..") ? 0 : -1;
}

int lf_dir_stage_begin(const char *dir, char *stage, size_t stage_size, lf_error *err)
{
    char parent[PATH_MAX], base[NAME_MAX + 1], prefix[NAME_MAX + 16];
    if (split_dir(dir, parent, sizeof parent, base, sizeof base))
        return lf_error_set(err, LF_ERR_PARAM, "'%s' cannot be an output folder", dir);
    int pl = snprintf(prefix, sizeof prefix, ".%s.stage", base);
    DIR *d = opendir(parent);
    for (struct dirent *e; d && (e = readdir(d));) {
        const char *r = e->d_name + pl;
        if (strncmp(e->d_name, prefix, (size_t)pl) || strlen(r) != 6)
            continue;
        char full[PATH_MAX * 2];
        snprintf(full, sizeof full, "%s%s", parent, e->d_name);
        struct stat st;
        if (lstat(full, &st) == 0 && S_ISDIR(st.st_mode))
            remove_flat_dir(full); /* a killed run's */
    }
    if (d)
        closedir(d);
    if (snprintf(stage, stage_size, "%s%sXXXXXX", parent, prefix) >= (int)stage_size)
        return lf_error_set(err, LF_ERR_PARAM, "path too long: %s", dir);
    if (!mkdtemp(stage))
        return lf_error_set(err, LF_ERR_IO, "cannot create directory %s: %s", dir, strerror(errno));
    chmod(stage, 0777 & ~current_umask());
    return LF_OK;
}

int lf_dir_stage_commit(const char *stage, const char *dir, lf_error *err)
{
    struct stat st;
    if (stat(dir, &st) != 0) {
        if (rename(stage, dir) == 0)
            return LF_OK;
        int e = errno;
        lf_dir_stage_abort(stage);
        return lf_error_set(err, LF_ERR_IO, "cannot create the folder %s: %s", dir, strerror(e));
    }
    if (!S_ISDIR(st.st_mode)) {
        lf_dir_stage_abort(stage);
        return lf_error_set(err, LF_ERR_IO, "%s exists and is not a folder", dir);
    }
    DIR *d = opendir(stage);
    int rc = d ? LF_OK : lf_error_set(err, LF_ERR_IO, "cannot read %s: %s", stage, strerror(errno));
    for (struct dirent *e; !rc && (e = readdir(d));) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        char from[PATH_MAX * 2], to[PATH_MAX * 2];
        snprintf(from, sizeof from, "%s/%s", stage, e->d_name);
        snprintf(to, sizeof to, "%s/%s", dir, e->d_name);
        if (rename(from, to))
            rc = lf_error_set(err, LF_ERR_IO, "cannot move %s into %s: %s", e->d_name, dir, strerror(errno));
    }
    if (d)
        closedir(d);
    lf_dir_stage_abort(stage);
    return rc;
}

void lf_dir_stage_abort(const char *stage)
{
    if (stage && *stage)
        remove_flat_dir(stage);
}
