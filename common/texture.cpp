#include "common/texture.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "common/image.h"
#include "common/oiio_module.h"

namespace rastray {

const char* toString(TextureFilter filter) {
  switch (filter) {
    case TextureFilter::Sampler:
      return "sampler";
    case TextureFilter::Nearest:
      return "nearest";
    case TextureFilter::Bilinear:
      return "bilinear";
    case TextureFilter::Trilinear:
      return "trilinear";
  }
  return "?";
}

namespace {

// `data`: a normal, occlusion or metallic-roughness map: bytes / 255,
// opaque (alpha carries nothing there, and must not weigh the filtering).
MipLevel decodeLevel0(const TextureImage& image, bool data) {
  MipLevel level;
  level.width = image.width;
  level.height = image.height;
  level.texels.resize(size_t(image.width) * size_t(image.height));
  float lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = srgbToLinear(i / 255.0f);
  for (size_t i = 0; i < level.texels.size(); ++i) {
    const uint8_t* p = &image.rgba8[i * 4];
    if (data) {
      level.texels[i] = glm::vec4(p[0] / 255.0f, p[1] / 255.0f, p[2] / 255.0f, 1.0f);
      continue;
    }
    const float a = p[3] / 255.0f;  // alpha is linear in glTF
    level.texels[i] = glm::vec4(lut[p[0]] * a, lut[p[1]] * a, lut[p[2]] * a, a);
  }
  return level;
}

MipLevel halve(const MipLevel& src) {
  MipLevel dst;
  dst.width = std::max(1, src.width / 2);
  dst.height = std::max(1, src.height / 2);
  dst.texels.resize(size_t(dst.width) * size_t(dst.height));
  oiioModule().resizeBox(src.width, src.height, src.texels.data(), dst.width, dst.height, dst.texels.data());
  return dst;
}

// The texel index in [0, n) along an axis of n texels for the integer
// texel coordinate i (any double: huge, infinite or NaN), under a glTF
// wrap mode. The wrap is done in double, where fmod is exact, and only its
// result, already in [0, n), is converted to int: no conversion can
// overflow, whatever the texture size or uv.
int wrap(double i, int n, int mode) {
  if (std::isnan(i)) i = 0.0;
  if (mode == 33071) return int(std::clamp(i, 0.0, double(n - 1)));  // CLAMP_TO_EDGE
  if (std::isinf(i)) i = 0.0;  // no period to follow: any texel is as good
  if (mode == 33648) {         // MIRRORED_REPEAT
    const double period = 2.0 * double(n);
    double m = std::fmod(i, period);
    if (m < 0.0) m += period;  // exact: m is an integer in (−period, 0)
    return int(m < double(n) ? m : period - 1.0 - m);
  }
  double m = std::fmod(i, double(n));  // REPEAT
  if (m < 0.0) m += double(n);
  return int(m);
}

glm::vec4 texel(const MipLevel& level, double x, double y, const TextureSampler& s) {
  const int ix = wrap(x, level.width, s.wrapS);
  const int iy = wrap(y, level.height, s.wrapT);
  return level.texels[size_t(iy) * size_t(level.width) + size_t(ix)];
}

// Texel centres sit at half-integers: uv (0, 0) is the top-left corner of
// texel (0, 0). Texel coordinates are formed in double: float uv times any
// int size stays finite there.
glm::vec4 nearest(const MipLevel& level, glm::vec2 uv, const TextureSampler& s) {
  return texel(level, std::floor(double(uv.x) * level.width), std::floor(double(uv.y) * level.height), s);
}

glm::vec4 bilinear(const MipLevel& level, glm::vec2 uv, const TextureSampler& s) {
  const double x = double(uv.x) * level.width - 0.5, y = double(uv.y) * level.height - 0.5;
  const double x0 = std::floor(x), y0 = std::floor(y);
  const float tx = float(x - x0), ty = float(y - y0);
  const glm::vec4 a = glm::mix(texel(level, x0, y0, s), texel(level, x0 + 1.0, y0, s), tx);
  const glm::vec4 b = glm::mix(texel(level, x0, y0 + 1.0, s), texel(level, x0 + 1.0, y0 + 1.0, s), tx);
  return glm::mix(a, b, ty);
}

glm::vec4 unpremultiply(const glm::vec4& c) {
  return c.a > 0.0f ? glm::vec4(glm::vec3(c) / c.a, c.a) : glm::vec4(0.0f);
}

}  // namespace

TextureSet::TextureSet(const Scene& scene) {
  chains_.resize(scene.textures.size());
  samplers_.resize(scene.textures.size());
  transforms_.resize(scene.textures.size());
  // Per image, its colour chain [0] and its data chain [1].
  std::vector<std::array<std::shared_ptr<const std::vector<MipLevel>>, 2>> byImage(scene.images.size());
  // Base colour and emissive textures are both sRGB colour: one chain
  // serves a texture used as either, and every texture of its image; the
  // data maps (Texture::data) share the image's linear chain.
  for (const Material& m : scene.materials)
    for (const int32_t texture : {m.baseColorTexture, m.emissiveTexture, m.normalTexture, m.occlusionTexture,
                                  m.metallicRoughnessTexture}) {
      if (texture < 0) continue;
      const size_t t = size_t(texture);
      samplers_[t] = scene.textures[t].sampler;
      transforms_[t] = scene.textures[t].transform;
      if (chains_[t]) continue;
      const size_t image = size_t(scene.textures[t].image);
      const bool data = scene.textures[t].data;
      auto& shared = byImage[image][data ? 1 : 0];
      if (!shared) {
        std::vector<MipLevel> chain;
        chain.push_back(decodeLevel0(scene.images[image], data));
        while (chain.back().width > 1 || chain.back().height > 1) chain.push_back(halve(chain.back()));
        shared = std::make_shared<const std::vector<MipLevel>>(std::move(chain));
      }
      chains_[t] = shared;
    }
}

size_t TextureSet::levelCount(int texture) const { return chains_[size_t(texture)]->size(); }

float TextureSet::levelOfDetail(int texture, const TextureFootprint& fp) const {
  const MipLevel& l0 = (*chains_[size_t(texture)])[0];
  // The footprint's derivatives map through the transform's linear part.
  const TextureTransform& transform = transforms_[size_t(texture)];
  const glm::vec2 dx = transform.applyLinear(fp.dUVdx), dy = transform.applyLinear(fp.dUVdy);
  const glm::vec2 size(float(l0.width), float(l0.height));
  const float rho = std::max(glm::length(dx * size), glm::length(dy * size));
  return rho > 0.0f ? std::log2(rho) : -INFINITY;
}

glm::vec4 TextureSet::sample(int texture, glm::vec2 uv, const TextureFootprint& fp,
                             TextureFilter filter) const {
  // KHR_texture_transform: uv affinely (the footprint in levelOfDetail).
  uv = transforms_[size_t(texture)].apply(uv);
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
  const std::vector<MipLevel>& chain = *chains_[size_t(texture)];
  const TextureSampler& s = samplers_[size_t(texture)];
  if (filter == TextureFilter::Nearest) return unpremultiply(nearest(chain[0], uv, s));
  if (filter == TextureFilter::Bilinear) return unpremultiply(bilinear(chain[0], uv, s));

  const float lambda = levelOfDetail(texture, fp);
  const int maxLevel = int(chain.size()) - 1;
  if (filter == TextureFilter::Sampler && !(lambda > 0.0f)) {
    // Magnification: the sampler's magFilter (unset: linear).
    return unpremultiply(s.magFilter == 9728 ? nearest(chain[0], uv, s) : bilinear(chain[0], uv, s));
  }
  int minFilter = filter == TextureFilter::Trilinear ? 9987 : s.minFilter;
  if (minFilter < 0) minFilter = 9987;  // unset: trilinear
  const bool linearInLevel = minFilter == 9729 || minFilter == 9985 || minFilter == 9987;
  auto lookup = [&](int level) {
    const MipLevel& l = chain[size_t(std::clamp(level, 0, maxLevel))];
    return linearInLevel ? bilinear(l, uv, s) : nearest(l, uv, s);
  };
  if (minFilter == 9728 || minFilter == 9729) return unpremultiply(lookup(0));  // no mip-mapping
  // NaN (a footprint of NaNs) reads as level 0, so the conversions below stay in range.
  const float lod = lambda > 0.0f ? std::min(lambda, float(maxLevel)) : 0.0f;
  if (minFilter == 9984 || minFilter == 9985) return unpremultiply(lookup(int(std::lround(lod))));
  const int lo = int(std::floor(lod));
  const float t = lod - float(lo);
  return unpremultiply(t > 0.0f ? glm::mix(lookup(lo), lookup(lo + 1), t) : lookup(lo));
}

std::shared_ptr<const TextureSet> SharedTextureSet::get(const Scene& scene) const {
  std::call_once(once_, [&] {
    set_ = std::make_shared<const TextureSet>(scene);
    scene_ = &scene;
  });
  return scene_ == &scene ? set_ : std::make_shared<const TextureSet>(scene);
}

}  // namespace rastray
