// Textures: sRGB decoding (base colour, emissive) or linear reading (the
// data maps: normal, occlusion, metallic-roughness; Texture::data), mip
// chains and filtered lookups, shared by both renderers.
//
// Mip chains are built in linear, premultiplied float RGBA (so filtering
// neither darkens nor fringes at alpha edges: a transparent texel adds no
// colour to its neighbours), each level a box-filtered half of the one
// above it (OpenImageIO's resize), down to 1×1. Lookups return straight
// (un-premultiplied) linear RGBA.
//
// Wrapping (REPEAT, MIRRORED_REPEAT, CLAMP_TO_EDGE) is exact for any
// finite uv and any texture size: texel coordinates are formed and wrapped
// in double and only the wrapped index in [0, size) becomes an int.
// Non-finite uv samples at uv (0, 0).
//
// Level of detail follows OpenGL: rho = max(|duv/dx|, |duv/dy|) in texels
// of level 0, lambda = log2(rho); lambda <= 0 magnifies.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include <glm/glm.hpp>

#include "common/scene.h"
#include "common/surface.h"

namespace rastray {

enum class TextureFilter {
  Sampler,    // as the glTF sampler says (unset: trilinear)
  Nearest,    // level 0, nearest texel
  Bilinear,   // level 0, bilinear
  Trilinear,  // bilinear in the two nearest levels, blended by lambda
};

const char* toString(TextureFilter filter);

struct MipLevel {
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;  // linear, premultiplied; row 0 = top = v 0
};

class TextureSet {
 public:
  TextureSet() = default;
  // Decodes and builds the chains of every texture a material uses. Leave
  // it empty (default constructor) for scenes that need no textures.
  explicit TextureSet(const Scene& scene);

  bool empty() const { return chains_.empty(); }
  size_t levelCount(int texture) const;
  const std::vector<MipLevel>& levels(int texture) const { return *chains_[size_t(texture)]; }

  // Straight linear RGBA at uv (the surface's) for a footprint: the
  // texture's transform (KHR_texture_transform, Texture::transform) maps uv
  // and the footprint first, inside this one function both renderers use.
  glm::vec4 sample(int texture, glm::vec2 uv, const TextureFootprint& footprint, TextureFilter filter) const;
  // The level of detail lambda for a footprint in the surface's uv (the
  // texture's transform applied here, as in sample).
  float levelOfDetail(int texture, const TextureFootprint& footprint) const;

 private:
  // By texture index; textures of one image share its chain (textureInfos
  // with a transform get textures of their own). Null for unused ones.
  std::vector<std::shared_ptr<const std::vector<MipLevel>>> chains_;
  std::vector<TextureSampler> samplers_;
  std::vector<TextureTransform> transforms_;
};

// A scene's TextureSet built once, on first use, and shared: every Shader
// of a frame (the camera's, the shadow maps', the ray caster's) and every
// frame of a bench run asks the same holder (SceneAnalysis::textureSet)
// instead of decoding and halving every texture again. Thread-safe.
class SharedTextureSet {
 public:
  // The set of `scene`; built on the first call. A different scene than the
  // first call's gets a set of its own, not kept.
  std::shared_ptr<const TextureSet> get(const Scene& scene) const;

 private:
  mutable std::once_flag once_;
  mutable std::shared_ptr<const TextureSet> set_;
  mutable const Scene* scene_ = nullptr;
};

}  // namespace rastray
