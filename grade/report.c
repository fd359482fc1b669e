/* report.c - per-student HTML reports and the grade book (CSV, JSON). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "base/lf_buf.h"
#include "grade_internal.h"

int lf_grade_report_student(const char *dir, const char *title, const lf_grade_result *r, lf_error *err);

static void html_escape(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

static int exists(const char *dir, const char *id, const char *what)
{
    char p[1400];
    struct stat st;
    snprintf(p, sizeof p, "%s/%s-%s.png", dir, id, what);
    return stat(p, &st) == 0;
}

static void num(FILE *f, const char *fmt, double v)
{
    if (isnan(v))
        fputs("&ndash;", f);
    else
        fprintf(f, fmt, v);
}

int lf_grade_report_student(const char *dir, const char *title, const lf_grade_result *r, lf_error *err)
{
    char path[1400], tmp[1420];
    snprintf(path, sizeof path, "%s/index.html", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "%s: cannot write: %s", tmp, strerror(errno));
    fputs("<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>", f);
    html_escape(f, r->student);
    fputs("</title>\n<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
          "td,th{border:1px solid #aaa;padding:3px 8px;text-align:left}.pass{color:#070}.fail{color:#b00}"
          "img{image-rendering:pixelated;width:256px;margin-right:6px}</style></head><body>\n<h1>",
          f);
    html_escape(f, title);
    fputs(": ", f);
    html_escape(f, r->student);
    fprintf(f, "</h1>\n<p>Proposed score: <b>%d / %d</b> (graded in %.2f s). Images: submission, reference, "
               "difference (per-pixel relative squared error over the Monte Carlo noise level: black &le; 1&times;, "
               "blue, green, yellow, red &ge; 100&times;).</p>\n",
            r->score, r->max, r->seconds);
    fputs("<table><tr><th>check</th><th>points</th><th>result</th><th>error / noise</th><th>SSIM (refs: "
          "noise)</th><th>PSNR dB</th><th>closest mistake</th></tr>\n",
          f);
    for (int i = 0; i < r->nchecks; i++) {
        const lf_grade_check_result *c = &r->checks[i];
        fputs("<tr><td>", f);
        html_escape(f, c->id);
        fprintf(f, "</td><td>%d / %d</td><td class=\"%s\">", c->earned, c->points,
                c->status == LF_GRADE_PASS ? "pass" : "fail");
        if (c->status == LF_GRADE_PASS)
            fputs("pass", f);
        else
            html_escape(f, c->reason);
        if (c->measurements[0] && (c->status == LF_GRADE_PASS || !strstr(c->reason, c->measurements))) {
            fputs("<br><small>measured: ", f);
            html_escape(f, c->measurements);
            fputs("</small>", f);
        }
        fputs("</td><td>", f);
        num(f, "%.2f&times;", c->noise_ratio);
        fputs("</td><td>", f);
        num(f, "%.3f", c->ssim);
        fputs(" (", f);
        num(f, "%.3f", c->ssim_noise);
        fputs(")</td><td>", f);
        num(f, "%.1f", c->psnr_db);
        fputs("</td><td>", f);
        html_escape(f, c->best_variant);
        fputs("</td></tr>\n", f);
    }
    fputs("</table>\n", f);
    for (int i = 0; i < r->nchecks; i++) {
        const lf_grade_check_result *c = &r->checks[i];
        if (!exists(dir, c->id, "submission"))
            continue;
        fputs("<h2>", f);
        html_escape(f, c->id);
        fputs("</h2>\n<p>", f);
        static const char *what[] = {"submission", "reference", "diff"};
        for (int k = 0; k < 3; k++)
            if (exists(dir, c->id, what[k])) {
                fputs("<img src=\"", f);
                html_escape(f, c->id);
                fprintf(f, "-%s.png\" alt=\"%s\" title=\"%s\">", what[k], what[k], what[k]);
            }
        fputs("</p>\n", f);
    }
    fputs("</body></html>\n", f);
    int bad = ferror(f);
    if (fclose(f) || bad || rename(tmp, path)) {
        remove(tmp);
        return lf_error_set(err, LF_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    }
    return 0;
}

/* JSON string with the required escapes. */
static void json_str(lf_strbuf *b, const char *s)
{
    lf_strbuf_puts(b, "\"");
    for (; *s; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\')
            lf_strbuf_printf(b, "\\%c", ch);
        else if (ch < 32)
            lf_strbuf_printf(b, "\\u%04x", ch);
        else
            lf_strbuf_append(b, s, 1);
    }
    lf_strbuf_puts(b, "\"");
}

static void json_num(lf_strbuf *b, double v)
{
    if (isfinite(v))
        lf_strbuf_printf(b, "%.6g", v);
    else
        lf_strbuf_puts(b, "null");
}

int lf_grade_failed_checks(const lf_grade_result *r)
{
    int n = 0;
    for (int k = 0; k < r->nchecks; k++)
        n += r->checks[k].status == LF_GRADE_FAIL;
    return n;
}

char *lf_grade_result_json(const lf_grade_result *r)
{
    lf_strbuf b = {0};
    lf_strbuf_printf(&b, "{\"student\": ");
    json_str(&b, r->student);
    lf_strbuf_printf(&b, ", \"path\": ");
    json_str(&b, r->path);
    lf_strbuf_printf(&b, ", \"score\": %d, \"max\": %d, \"seconds\": %.3f, \"checks\": [", r->score, r->max, r->seconds);
    for (int i = 0; i < r->nchecks; i++) {
        const lf_grade_check_result *c = &r->checks[i];
        lf_strbuf_printf(&b, "%s{\"id\": ", i ? ", " : "");
        json_str(&b, c->id);
        lf_strbuf_printf(&b, ", \"kind\": ");
        json_str(&b, c->kind);
        lf_strbuf_printf(&b, ", \"points\": %d, \"earned\": %d, \"passed\": %s, \"reason\": ", c->points, c->earned,
            c->status == LF_GRADE_PASS ? "true" : "false");
        json_str(&b, c->reason);
        lf_strbuf_printf(&b, ", \"noise_ratio\": ");
        json_num(&b, c->noise_ratio);
        lf_strbuf_printf(&b, ", \"ssim\": ");
        json_num(&b, c->ssim);
        lf_strbuf_printf(&b, ", \"psnr_db\": ");
        json_num(&b, c->psnr_db);
        lf_strbuf_printf(&b, ", \"closest_mistake\": ");
        json_str(&b, c->best_variant);
        lf_strbuf_printf(&b, ", \"measurements\": ");
        json_str(&b, c->measurements);
        lf_strbuf_printf(&b, "}");
    }
    lf_strbuf_printf(&b, "]}");
    if (b.failed) { /* out of memory: no half a document */
        lf_strbuf_free(&b);
        return NULL;
    }
    return lf_strbuf_take(&b);
}

static void csv_field(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"')
            fputc('"', f);
        fputc(*s == '\n' || *s == '\r' ? ' ' : *s, f);
    }
    fputc('"', f);
}

int lf_grade_write_gradebook(const char *dir, const lf_grade_result *res, int n, lf_error *err)
{
    char path[1400];
    snprintf(path, sizeof path, "%s/gradebook.csv", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    fputs("student,score,max", f);
    if (n > 0)
        for (int i = 0; i < res[0].nchecks; i++)
            fprintf(f, ",%s", res[0].checks[i].id);
    fputs(",reasons\n", f);
    for (int s = 0; s < n; s++) {
        const lf_grade_result *r = &res[s];
        char name[160];
        /* a leading = + - @ would make a spreadsheet evaluate a formula */
        snprintf(name, sizeof name, "%s%s", strchr("=+-@", r->student[0]) && r->student[0] ? "'" : "", r->student);
        csv_field(f, name);
        fprintf(f, ",%d,%d", r->score, r->max);
        for (int i = 0; i < r->nchecks; i++)
            fprintf(f, ",%d", r->checks[i].earned);
        char reasons[8192] = "";
        for (int i = 0; i < r->nchecks; i++)
            if (r->checks[i].status == LF_GRADE_FAIL) {
                size_t l = strlen(reasons);
                snprintf(reasons + l, sizeof reasons - l, "%s%s (-%d): %s", l ? " | " : "", r->checks[i].id,
                         r->checks[i].points - r->checks[i].earned, r->checks[i].reason);
            }
        fputc(',', f);
        csv_field(f, reasons);
        fputc('\n', f);
    }
    if (fclose(f))
        return lf_error_set(err, LF_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    snprintf(path, sizeof path, "%s/gradebook.json", dir);
    f = fopen(path, "w");
    if (!f)
        return lf_error_set(err, LF_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    fputs("[\n", f);
    for (int s = 0; s < n; s++) {
        char *j = lf_grade_result_json(&res[s]);
        if (!j) {
            fclose(f);
            remove(path);
            return lf_error_set(err, LF_ERR_NOMEM, "%s: out of memory", path);
        }
        fprintf(f, "  %s%s\n", j, s + 1 < n ? "," : "");
        free(j);
    }
    fputs("]\n", f);
    if (fclose(f))
        return lf_error_set(err, LF_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    return 0;
}
