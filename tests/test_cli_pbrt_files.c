/* lfrender on scenes from the wild (issue 18): gzipped files of every kind
 * render bit-identical to plain ones; Shape "loopsubdiv" renders exactly as
 * the triangle mesh it stands for; refused features exit 1 and write
 * nothing; several problems are reported together; --allow-unsupported. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "image/lf_image.h"
#include "lf_test.h"
#include "lf_test_tools.h"
#include "render/lf_subdiv.h"

static char dir[256];
static char out_text[65536];

static int exists(const char *rel)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, rel);
    struct stat s;
    return stat(p, &s) == 0;
}

static void write_file(const char *rel, const char *text)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, rel);
    FILE *f = fopen(p, "wb");
    if (!f)
        return;
    fputs(text, f);
    fclose(f);
}

/* Pixels of two EXRs are bit-identical. */
static int same_pixels(const char *a, const char *b)
{
    char pa[512], pb[512];
    snprintf(pa, sizeof pa, "%s/%s", dir, a);
    snprintf(pb, sizeof pb, "%s/%s", dir, b);
    lf_image ia, ib;
    lf_attrs xa = {0}, xb = {0};
    lf_error err = {0};
    if (lf_image_read(pa, &ia, &xa, &err) || lf_image_read(pb, &ib, &xb, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return 0;
    }
    int same = ia.width == ib.width && ia.height == ib.height && ia.channels == ib.channels &&
               memcmp(ia.data, ib.data, sizeof(float) * (size_t)ia.width * ia.height * ia.channels) == 0;
    double sum = 0;
    for (size_t i = 0; i < (size_t)ia.width * ia.height * ia.channels; i++)
        sum += ia.data[i];
    CHECK_MSG(sum > 0, "%s is black", a);
    lf_image_free(&ia);
    lf_image_free(&ib);
    lf_attrs_free(&xa);
    lf_attrs_free(&xb);
    return same;
}

static const double phi = 1.6180339887498949;
static const double ico_P[36] = {-1, phi, 0, 1, phi, 0, -1, -phi, 0, 1, -phi, 0, 0, -1, phi, 0, 1, phi,
                                 0, -1, -phi, 0, 1, -phi, phi, 0, -1, phi, 0, 1, -phi, 0, -1, -phi, 0, 1};
static const int ico_F[60] = {0, 11, 5, 0, 5, 1,  0, 1, 7,  0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                              4, 11, 10, 2, 10, 7, 6, 7, 1, 8,  3, 9, 4,  3, 4,  2,  3, 2, 6, 3,
                              6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6,  7,  9, 8, 1};

static void append(char *buf, size_t cap, const char *fmt, ...)
{
    size_t n = strlen(buf);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf + n, cap - n, fmt, ap);
    va_end(ap);
}

static const char *HEAD = "LookAt 0 0.5 7  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n"
                          "Film \"rgb\" \"integer xresolution\" 48 \"integer yresolution\" 40\n"
                          "Sampler \"sobol\" \"integer pixelsamples\" 8\nWorldBegin\n"
                          "LightSource \"distant\" \"point3 from\" [1 2 3] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3]\n"
                          "LightSource \"infinite\" \"rgb L\" [0.2 0.2 0.2]\n";

static void test_gzip_bit_identical(void)
{
    /* plain: main -> Include geometry (loopsubdiv + plymesh) and a
     * spectrum file for a conductor */
    char geo[8192] = "AttributeBegin\nTranslate -1.2 0 0\nMaterial \"conductor\" \"spectrum eta\" \"au.spd\" "
                     "\"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.2\n"
                     "Shape \"loopsubdiv\" \"integer levels\" 2 \"point3 P\" [";
    for (int i = 0; i < 36; i++)
        append(geo, sizeof geo, " %.17g", ico_P[i] * 0.6);
    append(geo, sizeof geo, "]\n  \"integer indices\" [");
    for (int i = 0; i < 60; i++)
        append(geo, sizeof geo, " %d", ico_F[i]);
    append(geo, sizeof geo, "]\nAttributeEnd\nTranslate 1.3 -0.5 0\nMaterial \"diffuse\" \"rgb reflectance\" [.7 .3 .2]\n"
                            "Shape \"plymesh\" \"string filename\" \"%%s\"\n");
    char geo_plain[8192], geo_gz[8192];
    snprintf(geo_plain, sizeof geo_plain, geo, "tet.ply");
    snprintf(geo_gz, sizeof geo_gz, geo, "tet.ply.gz");
    write_file("geo.pbrt", geo_plain);
    write_file("geo2.pbrt", geo_gz);
    write_file("tet.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
                          "0 1.2 0\n-1 -0.5 0.6\n1 -0.5 0.6\n0 -0.5 -1\n3 0 1 2\n3 0 2 3\n3 0 3 1\n3 1 3 2\n");
    write_file("au.spd", "# gold, n (a few samples)\n400 1.66\n450 1.38\n500 0.97\n550 0.43\n600 0.25\n650 0.17\n"
                         "700 0.16\n");
    char main_text[2048];
    snprintf(main_text, sizeof main_text, "%sInclude \"geo.pbrt\"\n", HEAD);
    write_file("main.pbrt", main_text);
    snprintf(main_text, sizeof main_text, "%sInclude \"geo2.pbrt.gz\"\n", HEAD);
    /* au.spd is named as is but compressed: detection is by magic bytes */
    write_file("main2.pbrt", main_text);
    CHECK(run("cp au.spd au.spd.orig && gzip -n -f geo2.pbrt main2.pbrt && gzip -n -k -f tet.ply && "
              "mkdir -p gz && gzip -n -c au.spd.orig > gz/au.spd") == 0);
    /* the gzipped scene lives in gz/ (its own au.spd, compressed), with
     * links to the compressed geometry */
    CHECK(run("mv main2.pbrt.gz gz/ && mv geo2.pbrt.gz gz/ && cp tet.ply.gz gz/") == 0);
    CHECK_MSG(run("%s main.pbrt -o plain.exr --quiet --seed 3", LF_LFRENDER) == 0, "%s", out_text);
    CHECK_MSG(run("%s gz/main2.pbrt.gz -o gz.exr --quiet --seed 3", LF_LFRENDER) == 0, "%s", out_text);
    CHECK_MSG(same_pixels("plain.exr", "gz.exr"), "gzipped scene differs from the plain one");

    /* a mesh named relative to the main file from a nested include (pbrt-v4's
     * rule) renders like the flat layout */
    CHECK(run("mkdir -p nest/geometry && cp tet.ply nest/geometry/ && cp au.spd.orig nest/au.spd && "
              "sed 's|\"tet.ply\"|\"geometry/tet.ply\"|' geo.pbrt > nest/geometry/geo.pbrt && "
              "sed 's|Include \"geo.pbrt\"|Include \"geometry/geo.pbrt\"|' main.pbrt > nest/main.pbrt") == 0);
    CHECK_MSG(run("%s nest/main.pbrt -o nest.exr --quiet --seed 3", LF_LFRENDER) == 0, "%s", out_text);
    CHECK_MSG(same_pixels("plain.exr", "nest.exr"), "nested layout renders differently");

    /* a gzipped lens prescription (realistic camera) */
    CHECK(run("cp %s/scenes/lenses/dgauss.50mm.dat lens.dat && gzip -n -c lens.dat > lensz.dat", LF_SOURCE_DIR) == 0);
    const char *cam = "LookAt 0 0.5 7  0 0 0  0 1 0\nCamera \"realistic\" \"string lensfile\" \"%s\" "
                      "\"float aperturediameter\" 10 \"float focusdistance\" 7\n"
                      "Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 24 \"float diagonal\" 35\n"
                      "Sampler \"sobol\" \"integer pixelsamples\" 4\nWorldBegin\n"
                      "LightSource \"infinite\" \"rgb L\" [1 1 1]\nInclude \"geo.pbrt\"\n";
    char lens_scene[1024];
    snprintf(lens_scene, sizeof lens_scene, cam, "lens.dat");
    write_file("lens.pbrt", lens_scene);
    snprintf(lens_scene, sizeof lens_scene, cam, "lensz.dat");
    write_file("lensz.pbrt", lens_scene);
    CHECK_MSG(run("%s lens.pbrt -o lens.exr --quiet", LF_LFRENDER) == 0, "%s", out_text);
    CHECK_MSG(run("%s lensz.pbrt -o lensz.exr --quiet", LF_LFRENDER) == 0, "%s", out_text);
    CHECK_MSG(same_pixels("lens.exr", "lensz.exr"), "gzipped lens file renders differently");

    /* a corrupt gzipped PLY: exit 1, the file named, nothing written */
    CHECK(run("head -c 60 tet.ply.gz > gz/bad.ply.gz && sed 's/tet.ply.gz/bad.ply.gz/' geo.pbrt > gz/geo3.pbrt") == 0);
    snprintf(main_text, sizeof main_text, "%sInclude \"geo3.pbrt\"\n", HEAD);
    write_file("gz/main3.pbrt", main_text);
    CHECK(run("sed -i 's/tet.ply/bad.ply.gz/' gz/geo3.pbrt") == 0);
    CHECK(run("%s gz/main3.pbrt -o bad.exr --quiet", LF_LFRENDER) == 1);
    CHECK_MSG(strstr(out_text, "bad.ply.gz") && strstr(out_text, "corrupt gzip") && strstr(out_text, "geo3.pbrt:"),
              "%s", out_text);
    CHECK(!exists("bad.exr"));
}

/* An image texture and an environment map named in a nested include
 * relative to the top-level scene (pbrt-v4 resolves every relative name
 * there; sanmiguel's geometry/ *-mat.pbrt files name "textures/..." that way)
 * render like the same files named next to the including file; a name
 * found in neither place is reported with the path tried first. */
static void test_nested_image_files(void)
{
    CHECK(run("mkdir -p flat/textures nested/geometry nested/textures") == 0);
    /* a 2x2 PFM, rows of different colours */
    char pfm[512];
    snprintf(pfm, sizeof pfm, "%s/flat/textures/t.pfm", dir);
    FILE *f = fopen(pfm, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    float px[12] = {0.2f, 0.4f, 0.6f, 0.2f, 0.4f, 0.6f, 0.7f, 0.3f, 0.1f, 0.7f, 0.3f, 0.1f};
    fprintf(f, "PF\n2 2\n-1.0\n");
    CHECK(fwrite(px, sizeof px, 1, f) == 1);
    fclose(f);
    CHECK(run("cp flat/textures/t.pfm nested/textures/") == 0);
    const char *main_fmt = "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n"
                           "LookAt 0 0 3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n"
                           "Sampler \"sobol\" \"integer pixelsamples\" 4\nWorldBegin\nInclude \"%s\"\n"
                           "Shape \"trianglemesh\" \"point3 P\" [-1 -1 0 1 -1 0 1 1 0 -1 1 0] "
                           "\"integer indices\" [0 1 2 0 2 3] \"point2 uv\" [0 0 1 0 1 1 0 1]\n";
    const char *inc = "LightSource \"infinite\" \"string filename\" \"textures/t.pfm\"\n"
                      "Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"textures/t.pfm\"\n"
                      "Material \"diffuse\" \"texture reflectance\" \"t\"\n";
    char text[2048];
    snprintf(text, sizeof text, main_fmt, "inc.pbrt");
    write_file("flat/main.pbrt", text);
    write_file("flat/inc.pbrt", inc);
    snprintf(text, sizeof text, main_fmt, "geometry/inc.pbrt");
    write_file("nested/main.pbrt", text);
    write_file("nested/geometry/inc.pbrt", inc);
    CHECK_MSG(run("%s flat/main.pbrt -o flat.exr --quiet --seed 5", LF_LFRENDER) == 0, "%s", out_text);
    CHECK_MSG(run("%s nested/main.pbrt -o nested.exr --quiet --seed 5", LF_LFRENDER) == 0, "%s", out_text);
    CHECK_MSG(same_pixels("flat.exr", "nested.exr"), "nested image files render differently");
    /* in neither place: exit 1, the first candidate named */
    CHECK(run("rm nested/textures/t.pfm") == 0);
    CHECK(run("%s nested/main.pbrt -o gone.exr --quiet", LF_LFRENDER) == 1);
    CHECK_MSG(strstr(out_text, "nested/geometry/textures/t.pfm"), "%s", out_text);
    CHECK(!exists("gone.exr"));
}

/* Shape "loopsubdiv" renders bit-identical to the trianglemesh holding its
 * limit positions and normals: the subdivision reaches the mesh path intact. */
static void test_loopsubdiv_as_trianglemesh(void)
{
    lf_ply_mesh m;
    lf_error err = {0};
    if (lf_loop_subdivide(ico_P, 12, ico_F, 20, 2, &m, &err)) {
        CHECK_MSG(0, "%s", err.msg);
        return;
    }
    size_t cap = 1 << 20;
    char *a = malloc(cap), *b = malloc(cap);
    snprintf(a, cap, "%sMaterial \"coateddiffuse\"\nShape \"loopsubdiv\" \"integer levels\" 2 \"point3 P\" [", HEAD);
    for (int i = 0; i < 36; i++)
        append(a, cap, " %.17g", ico_P[i]);
    append(a, cap, "] \"integer indices\" [");
    for (int i = 0; i < 60; i++)
        append(a, cap, " %d", ico_F[i]);
    append(a, cap, "]\n");
    snprintf(b, cap, "%sMaterial \"coateddiffuse\"\nShape \"trianglemesh\" \"point3 P\" [", HEAD);
    for (size_t i = 0; i < 3 * m.n_vertices; i++)
        append(b, cap, " %.9g", m.P[i]);
    append(b, cap, "] \"normal N\" [");
    for (size_t i = 0; i < 3 * m.n_vertices; i++)
        append(b, cap, " %.9g", m.N[i]);
    append(b, cap, "] \"integer indices\" [");
    for (size_t i = 0; i < 3 * m.n_triangles; i++)
        append(b, cap, " %d", m.indices[i]);
    append(b, cap, "]\n");
    write_file("loop.pbrt", a);
    write_file("tri.pbrt", b);
    free(a);
    free(b);
    lf_ply_free(&m);
    CHECK_MSG(run("%s loop.pbrt -o loop.exr --quiet", LF_LFRENDER) == 0, "%s", out_text);
    CHECK_MSG(run("%s tri.pbrt -o tri.exr --quiet", LF_LFRENDER) == 0, "%s", out_text);
    CHECK_MSG(same_pixels("loop.exr", "tri.exr"), "loopsubdiv and its trianglemesh render differently");
}

static void test_refused(void)
{
    /* what the scene shows: each exits 1, names the directive, file:line:col
     * and "not supported", and writes nothing */
    const char *refused[] = {
        "Shape \"teapot\"",
        "Material \"velvet\"\nShape \"sphere\"",
        "MakeNamedMaterial \"m\" \"string type\" \"velvet\"\nShape \"sphere\"",
        "LightSource \"goniometric\" \"string filename\" \"x.exr\"",
        "LightSource \"projection\" \"string filename\" \"x.exr\"",
        "Texture \"t\" \"float\" \"ptex\" \"string filename\" \"t.ptx\"\nShape \"sphere\"",
    };
    const char *directive[] = {"unknown shape \"teapot\"", "unknown material \"velvet\"",
                               "MakeNamedMaterial: unknown material \"velvet\"", "LightSource \"goniometric\"",
                               "LightSource \"projection\"", "Texture \"ptex\" is not supported"};
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++) {
        char text[2048];
        snprintf(text, sizeof text, "%s%s\n", HEAD, refused[i]);
        write_file("refused.pbrt", text);
        CHECK(run("rm -f refused.exr refused.png") == 0);
        int rc = run("%s refused.pbrt -o refused.exr --quiet", LF_LFRENDER);
        CHECK_MSG(rc == 1, "%s: exit %d: %s", refused[i], rc, out_text);
        CHECK_MSG(strstr(out_text, "refused.pbrt:8:") && strstr(out_text, "not supported") &&
                      strstr(out_text, directive[i]),
                  "%s: %s", refused[i], out_text);
        CHECK_MSG(!exists("refused.exr"), "%s: an output was written", refused[i]);
        /* --allow-unsupported renders the rest with a warning */
        {
            rc = run("%s refused.pbrt -o refused.exr --quiet --allow-unsupported", LF_LFRENDER);
            CHECK_MSG(rc == 0 && exists("refused.exr") && strstr(out_text, "warning:") &&
                          strstr(out_text, "not supported"),
                      "%s with --allow-unsupported: exit %d: %s", refused[i], rc, out_text);
        }
    }

    /* parameters pbrt-v4 dropped (zero-day's Film "scale", transparent-
     * machines' "rrthreshold", explosion's "LeScale", renamed "Lescale"):
     * refused as pbrt-v4 refuses them, even with --allow-unsupported, with
     * what to do instead */
    const char *dropped[] = {
        "Film \"rgb\" \"float scale\" 3\nWorldBegin\n",
        "Integrator \"volpath\" \"float rrthreshold\" 0\nWorldBegin\n",
        "WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float LeScale\" 2\n",
    };
    const char *said[] = {
        "dropped.pbrt:1:12: unused parameter \"float scale\" in Film \"rgb\" (early pbrt-v4's film scale factor; "
        "pbrt-v4 no longer reads it",
        "dropped.pbrt:1:22: unused parameter \"float rrthreshold\" in Integrator \"volpath\" (pbrt-v3's and early "
        "pbrt-v4's",
        "dropped.pbrt:2:49: unused parameter \"float LeScale\" in MakeNamedMedium \"m\" (did you mean \"float "
        "Lescale\"?)",
    };
    for (size_t i = 0; i < sizeof dropped / sizeof dropped[0]; i++) {
        write_file("dropped.pbrt", dropped[i]);
        int rc = run("%s dropped.pbrt -o dropped.exr --quiet --allow-unsupported", LF_LFRENDER);
        CHECK_MSG(rc == 1 && strstr(out_text, said[i]), "%s: exit %d: %s", dropped[i], rc, out_text);
        CHECK(!exists("dropped.exr"));
    }

    /* three problems, three messages, one run */
    char text[2048];
    snprintf(text, sizeof text,
             "%sLightSource \"projection\" \"string filename\" \"x.exr\"\nShape \"sphere\" \"float radius\" \"big\"\n"
             "Shape \"sphere\"\nTexture \"p\" \"float\" \"ptex\"\nShape \"disk\"\n",
             HEAD);
    write_file("three.pbrt", text);
    CHECK(run("%s three.pbrt -o three.exr --quiet", LF_LFRENDER) == 1);
    CHECK_MSG(strstr(out_text, "three.pbrt:8:1: LightSource \"projection\" is not supported") &&
                  strstr(out_text, "three.pbrt:9:31: parameter \"float radius\" expects numbers") &&
                  strstr(out_text, "three.pbrt:11:1: Texture \"ptex\" is not supported") &&
                  strstr(out_text, "3 errors in three.pbrt"),
              "%s", out_text);
    CHECK(!exists("three.exr"));
}

int main(void)
{
    lf_test_run_setup(dir, 1, out_text, sizeof out_text);
    snprintf(dir, sizeof dir, "/tmp/lf_cli_pbrt_XXXXXX");
    if (!mkdtemp(dir)) {
        fprintf(stderr, "cannot make a temporary directory\n");
        return 1;
    }
    test_gzip_bit_identical();
    test_loopsubdiv_as_trianglemesh();
    test_nested_image_files();
    test_refused();
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (lf_test_failed == 0 && system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return lf_test_end();
}
