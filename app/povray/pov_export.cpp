#include "app/povray/pov_export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/math_constants.h"

namespace rastray {

namespace {

// 9 significant digits read back as the same float; 17 as the same double.
std::string num(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(v));
  return buf;
}

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

template <typename V>
std::string vec(const V& v) {
  return "<" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ">";
}

void writeCamera(std::ostringstream& out, const Camera& camera) {
  const PovCamera c = povCamera(camera);
  out << "// rastray's camera: " << camera.describe() << "\n";
  out << "camera {\n  " << (c.orthographic ? "orthographic" : "perspective") << "\n  location "
      << vec(c.location) << "\n  direction " << vec(c.direction) << "\n  right " << vec(c.right) << "\n  up "
      << vec(c.up) << "\n}\n\n";
}

void writeLights(std::ostringstream& out, const Scene& scene) {
  // Directional lights sit outside the bounding sphere: POV-Ray's parallel
  // light shadows only what lies on the far side of its location's plane.
  glm::dvec3 centre(0.0);
  double radius = 1.0;
  if (!scene.bounds.empty()) {
    centre = 0.5 * (scene.bounds.lo + scene.bounds.hi);
    radius = std::max(1.0, 0.5 * glm::length(scene.bounds.hi - scene.bounds.lo));
  }
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    out << "// light " << i << " '" << light.name << "' (" << toString(light.type) << ")\n";
    out << "light_source {\n";
    if (light.type == LightType::Directional) {
      out << "  " << vec(centre - 4.0 * radius * light.direction) << "\n  color rgb " << vec(light.color)
          << "\n  parallel\n  point_at " << vec(centre) << "\n";
    } else {
      out << "  " << vec(light.position) << "\n  color rgb " << vec(light.color) << "\n";
      if (light.type == LightType::Spot)
        out << "  spotlight\n  point_at " << vec(light.position + light.direction) << "\n  radius "
            << num(double(light.innerConeAngle) * 180.0 / kPi) << "\n  falloff "
            << num(double(light.outerConeAngle) * 180.0 / kPi) << "\n  tightness 0\n";
    }
    out << "}\n";
  }
  out << "\n";
}

void writeInstance(std::ostringstream& out, const Scene& scene, uint32_t index) {
  const Instance& inst = scene.instances[index];
  const Material& m = scene.materials[inst.material];
  out << "// instance " << index << ": node " << inst.node << ", mesh " << inst.mesh << " primitive "
      << inst.primitive << ", material '" << m.name << "'\n";
  out << "mesh2 {\n  vertex_vectors {\n    " << inst.vertexCount;
  for (uint32_t v = 0; v < inst.vertexCount; ++v)
    out << ",\n    " << vec(scene.positions[inst.firstVertex + v]);
  out << "\n  }\n";
  const bool smooth = inst.normals == NormalSource::Authored;
  if (smooth) {
    out << "  normal_vectors {\n    " << inst.vertexCount;
    for (uint32_t v = 0; v < inst.vertexCount; ++v)
      out << ",\n    " << vec(scene.normals[inst.firstVertex + v]);
    out << "\n  }\n";
  }
  out << "  face_indices {\n    " << inst.triangleCount;
  for (uint32_t t = 0; t < inst.triangleCount; ++t) {
    const glm::uvec3 tri = scene.triangles[inst.firstTriangle + t] - glm::uvec3(inst.firstVertex);
    out << ",\n    <" << tri.x << ", " << tri.y << ", " << tri.z << ">";
  }
  out << "\n  }\n";
  const glm::vec3 c(m.baseColorFactor);
  out << "  texture {\n    pigment { color rgb " << vec(c)
      << " }\n    finish { ambient 0 emission 0 diffuse 1 specular 0 phong 0 reflection 0 }\n  }\n}\n";
}

}  // namespace

PovCamera povCamera(const Camera& camera) {
  // x_ndc = 2·x0 and y_ndc = 2·y0 at POV-Ray's pixel centres; the view
  // direction through NDC (x, y) is x·sx·X + y·sy·Y − Z (PrimaryRays).
  const glm::dmat4& m = camera.worldFromView;
  const glm::dvec2 scale = camera.ndcScale();
  PovCamera c;
  c.orthographic = camera.projection == Projection::Orthographic;
  c.location = camera.eye();
  c.direction = -glm::dvec3(m[2]);
  c.right = 2.0 * scale.x * glm::dvec3(m[0]);
  c.up = 2.0 * scale.y * glm::dvec3(m[1]);
  return c;
}

void makeOpaqueDiffuse(Scene& scene) {
  for (Material& m : scene.materials) {
    m.alphaMode = AlphaMode::Opaque;
    m.metallic = 0.0f;
    m.roughness = 1.0f;
    m.transmission = 0.0f;
    m.emissive = glm::vec3(0.0f);
    m.emissiveTexture = -1;
    // The maps would tilt normals and move the mirror weight: diffuse means flat.
    m.normalTexture = m.occlusionTexture = m.metallicRoughnessTexture = -1;
  }
}

std::string povSceneText(const Scene& scene, const Camera& camera) {
  std::ostringstream out;
  out << "// " << scene.path << " as rastray flattens it, every material opaque and diffuse.\n"
      << "// Written by `rastray povray --pov`. Render it as rastray's 1-spp frame:\n"
      << "//   povray "
      << "+I<this file> +O<out>.exr +FE +W" << camera.width << " +H" << camera.height
      << " -A -D -P +WT1 +Q4   (shadows; +Q3: without)\n"
      << "// Positions are relative to rastray's render origin " << vec(scene.origin) << ".\n"
      << "#version 3.7;\n"
      << "global_settings { assumed_gamma 1.0 ambient_light rgb 0 max_trace_level 1 }\n"
      << "background { color rgb 0 }\n\n";
  writeCamera(out, camera);
  writeLights(out, scene);
  for (uint32_t i = 0; i < scene.instances.size(); ++i)
    if (scene.instances[i].triangleCount > 0) writeInstance(out, scene, i);
  return out.str();
}

std::vector<std::string> povrayArguments(const std::string& input, const std::string& output, int width,
                                         int height, bool shadows) {
  return {"+I" + input,
          "+O" + output,
          "+FE",
          "+W" + std::to_string(width),
          "+H" + std::to_string(height),
          "-A",
          "-D",
          "-P",
          "-V",
          "+WT1",
          shadows ? "+Q4" : "+Q3"};
}

}  // namespace rastray
