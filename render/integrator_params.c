/* pbrt-v4's parameters of the integrators lensfield replaces by its path
 * tracer (render/integrator_params.h).  Names, types and defaults as in
 * pbrt-v4's src/pbrt/cpu/integrators.cpp Create functions. */
#include <string.h>

#include "render/integrator_params.h"

typedef enum { P_INT, P_FLOAT, P_BOOL } ptype;

static const struct {
    const char *integrator, *name;
    ptype type;
} foreign_params[] = {
    {"bdpt", "visualizestrategies", P_BOOL},
    {"bdpt", "visualizeweights", P_BOOL},
    {"mlt", "bootstrapsamples", P_INT},
    {"mlt", "chains", P_INT},
    {"mlt", "mutationsperpixel", P_INT},
    {"mlt", "largestepprobability", P_FLOAT},
    {"mlt", "sigma", P_FLOAT},
    {"sppm", "photonsperiteration", P_INT},
    {"sppm", "radius", P_FLOAT},
    {"sppm", "seed", P_INT},
    {"simplepath", "samplelights", P_BOOL},
    {"simplepath", "samplebsdf", P_BOOL},
};

int lf_integrator_accept_params(const char *type, lf_paramset *ps)
{
    int given = 0;
    for (size_t i = 0; i < sizeof foreign_params / sizeof foreign_params[0]; i++) {
        if (strcmp(foreign_params[i].integrator, type) != 0 || !lf_params_peek(ps, foreign_params[i].name))
            continue;
        given++;
        /* Read with the declared type: "float chains" is an error here as in pbrt-v4. */
        switch (foreign_params[i].type) {
        case P_INT:
            lf_params_int(ps, foreign_params[i].name, 0);
            break;
        case P_FLOAT:
            lf_params_float(ps, foreign_params[i].name, 0);
            break;
        case P_BOOL:
            lf_params_bool(ps, foreign_params[i].name, 0);
            break;
        }
    }
    return given;
}
