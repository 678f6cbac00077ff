// Tangent frames for normal maps (glTF 2.0 §3.7.2.1): when a primitive with
// a normal texture has no TANGENT attribute, glTF asks for MikkTSpace
// tangents. This is our own implementation of that convention, in double,
// per triangle corner (docs/MATERIALS.md "Tangents" says how close it is to
// the reference implementation):
//
//   1. Per face, the tangent (direction of increasing u) and the sign of
//      the uv area from positions and uvs: with position edges d1, d2 and
//      uv edges (s1, t1), (s2, t2), T = t2·d1 − t1·d2 and area = s1·t2 −
//      s2·t1; T is flipped with the area's sign, so it points along +u for
//      mirrored faces too. A face whose uv (or position) area is zero has
//      no tangent of its own.
//   2. Per corner, T projected onto the plane of the corner's normal (the
//      vertex normal, or the face normal without one), normalised, and
//      weighted by the corner's angle (measured between the edges
//      projected onto that plane).
//   3. Corners are grouped by welded vertex — equal position, normal and
//      uv, compared as values (not as indices, as MikkTSpace welds) — and
//      by orientation (the sign of the uv area): a vertex on a mirror seam
//      gets one tangent for each side. The group's tangent is the
//      normalised sum of its corners' weighted tangents; a face without a
//      tangent of its own takes the first group of its vertex that has one.
//   4. Handedness w = −1 where the uv area is positive, +1 where negative:
//      glTF's v axis points down the image while its normal maps' green
//      channel points up it, so the bitangent cross(n, T)·w points along −v
//      (as three.js's generator negates MikkTSpace's sign for glTF).
//      Corners with no tangent at all (every face around them degenerate in
//      uv) get any unit vector perpendicular to the normal, w = +1.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace rastray {

// Tangents (xyz unit, w = ±1) for corner k of triangle t at [3t + k], in the
// space of `positions` (object space: the loader transforms them after).
// `normals` is empty (face normals) or parallel to positions; so is `uvs`.
std::vector<glm::dvec4> generateTangents(const std::vector<glm::dvec3>& positions,
                                         const std::vector<glm::dvec3>& normals,
                                         const std::vector<glm::dvec2>& uvs,
                                         const std::vector<glm::uvec3>& triangles);

}  // namespace rastray
