#include "common/gltf/tangents.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>

namespace rastray {

namespace {

// Unit vector perpendicular to unit n (any: for corners without a tangent).
glm::dvec3 anyPerpendicular(const glm::dvec3& n) {
  const glm::dvec3 axis = std::abs(n.x) < 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
  const glm::dvec3 t = axis - n * glm::dot(n, axis);
  return glm::normalize(t);
}

// v projected onto the plane of unit n, normalised; zero when v lies along n.
glm::dvec3 projectedUnit(const glm::dvec3& v, const glm::dvec3& n) {
  const glm::dvec3 p = v - n * glm::dot(n, v);
  const double length = glm::length(p);
  return length > 0.0 && std::isfinite(length) ? p / length : glm::dvec3(0.0);
}

}  // namespace

std::vector<glm::dvec4> generateTangents(const std::vector<glm::dvec3>& positions,
                                         const std::vector<glm::dvec3>& normals,
                                         const std::vector<glm::dvec2>& uvs,
                                         const std::vector<glm::uvec3>& triangles) {
  const size_t faces = triangles.size();
  struct Face {
    glm::dvec3 tangent{0.0};  // unit, along +u; zero: none
    bool orientPreserving = true;
    glm::dvec3 normal{0.0, 0.0, 1.0};
  };
  std::vector<Face> face(faces);
  for (size_t f = 0; f < faces; ++f) {
    const glm::uvec3 t = triangles[f];
    const glm::dvec3 d1 = positions[t.y] - positions[t.x], d2 = positions[t.z] - positions[t.x];
    const glm::dvec2 uv0 = uvs.empty() ? glm::dvec2(0.0) : uvs[t.x];
    const glm::dvec2 e1 = uvs.empty() ? glm::dvec2(0.0) : uvs[t.y] - uv0;
    const glm::dvec2 e2 = uvs.empty() ? glm::dvec2(0.0) : uvs[t.z] - uv0;
    const glm::dvec3 n = glm::cross(d1, d2);
    const double nl = glm::length(n);
    if (nl > 0.0 && std::isfinite(nl)) face[f].normal = n / nl;
    const double area = e1.x * e2.y - e2.x * e1.y;
    face[f].orientPreserving = area > 0.0;
    const glm::dvec3 tangent = (area > 0.0 ? 1.0 : -1.0) * (e2.y * d1 - e1.y * d2);
    const double tl = glm::length(tangent);
    if (area != 0.0 && nl > 0.0 && tl > 0.0 && std::isfinite(tl)) face[f].tangent = tangent / tl;
  }

  // Weld corners by value: (position, normal, uv, orientation) → group.
  using Key = std::tuple<double, double, double, double, double, double, double, double, bool>;
  auto normalOf = [&](size_t f, int k) {
    if (normals.empty()) return face[f].normal;
    const glm::dvec3 n = normals[triangles[f][k]];
    const double l = glm::length(n);
    return l > 0.0 && std::isfinite(l) ? n / l : face[f].normal;
  };
  auto keyOf = [&](size_t f, int k, bool orient) {
    const uint32_t v = triangles[f][k];
    const glm::dvec3 p = positions[v];
    const glm::dvec3 n = normals.empty() ? face[f].normal : normals[v];
    const glm::dvec2 uv = uvs.empty() ? glm::dvec2(0.0) : uvs[v];
    return Key{p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y, orient};
  };
  std::map<Key, glm::dvec3> sum;
  for (size_t f = 0; f < faces; ++f) {
    if (face[f].tangent == glm::dvec3(0.0)) continue;
    const glm::uvec3 t = triangles[f];
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 n = normalOf(f, k);
      const glm::dvec3 p = positions[t[k]];
      // The corner's angle, between its edges projected onto n's plane.
      const glm::dvec3 a = projectedUnit(positions[t[(k + 1) % 3]] - p, n);
      const glm::dvec3 b = projectedUnit(positions[t[(k + 2) % 3]] - p, n);
      const double angle = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
      sum[keyOf(f, k, face[f].orientPreserving)] += angle * projectedUnit(face[f].tangent, n);
    }
  }

  std::vector<glm::dvec4> out(3 * faces);
  for (size_t f = 0; f < faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 n = normalOf(f, k);
      glm::dvec3 tangent(0.0);
      bool orient = face[f].orientPreserving;
      auto lookup = [&](bool o) {
        const auto it = sum.find(keyOf(f, k, o));
        if (it == sum.end()) return false;
        const glm::dvec3 unit = projectedUnit(it->second, n);
        if (unit == glm::dvec3(0.0)) return false;
        tangent = unit;
        orient = o;
        return true;
      };
      const bool own = face[f].tangent != glm::dvec3(0.0);
      // A face without a tangent of its own joins either orientation's group.
      const bool found = own ? lookup(orient) : (lookup(true) || lookup(false));
      if (!found) {
        out[3 * f + size_t(k)] = glm::dvec4(anyPerpendicular(n), 1.0);
        continue;
      }
      out[3 * f + size_t(k)] = glm::dvec4(tangent, orient ? -1.0 : 1.0);
    }
  }
  return out;
}

}  // namespace rastray
