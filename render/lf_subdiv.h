/* lf_subdiv.h - Loop subdivision surfaces (pbrt-v4's Shape "loopsubdiv").
 *
 *   lf_ply_mesh out;  // triangles, limit positions, limit normals
 *   if (lf_loop_subdivide(P, nv, indices, nt, 3, &out, &err)) ... err.msg ...
 *   ... lf_ply_free(&out);
 *
 * Charles Loop, "Smooth Subdivision Surfaces Based on Triangles" (MS thesis,
 * University of Utah, 1987), with the rules pbrt-v4 uses (docs/scene-format.md):
 *   - new edge ("odd") vertices: 3/8 of each end plus 1/8 of the two
 *     opposite vertices; on a boundary edge (one face), the midpoint;
 *   - old ("even") vertices of valence n: (1 - n b) v + b * sum(one ring)
 *     with b = 3/16 for n = 3 and 3/(8n) otherwise; on the boundary
 *     3/4 v + 1/8 of its two boundary neighbours;
 *   - after the last level every vertex moves to its limit position, interior
 *     with g = 1 / (n + 3/(8b)): (1 - n g) v + g * sum(ring), boundary
 *     3/5 v + 1/5 of its boundary neighbours;
 *   - normals are the cross product of the two limit tangents (interior:
 *     sums of the ring weighted by cos and sin of 2 pi j / n; boundary: the
 *     boundary chord and Loop's/Hoppe's across-boundary mask).
 * Boundaries (edges used by one triangle) are the only creases: pbrt-v4 has
 * no crease tags.  The control mesh should be an oriented 2-manifold with
 * boundary.  Where it is not (an edge used by three triangles, or by two
 * that run it the same way) the edge is treated as two boundary edges, and
 * triangles repeating a vertex are dropped, so real-world meshes still
 * subdivide (pbrt-v4 leaves such edges unshared too).
 */
#ifndef LF_SUBDIV_H
#define LF_SUBDIV_H

#include <stddef.h>

#include "base/lf_error.h"
#include "scenefile/lf_scene_desc.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Most levels accepted (each multiplies the triangle count by 4). */
#define LF_LOOP_MAX_LEVELS 10

/* Subdivides the control mesh (nv points P, 3 doubles each; nt triangles,
 * 3 indices each) `levels` times and returns the limit surface as a triangle
 * mesh with per-vertex normals (out->uv is NULL).  levels may be 0 (the
 * control mesh's vertices still move to the limit surface, as in pbrt-v4).
 * Vertices no triangle uses are kept, with normal (0,0,0).  Returns 0 or an
 * LF_ERR_* code with a message in err. */
int lf_loop_subdivide(const double *P, size_t nv, const int *indices, size_t nt, int levels, lf_ply_mesh *out,
                      lf_error *err);

#ifdef __cplusplus
}
#endif
#endif
