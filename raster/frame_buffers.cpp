#include "raster/frame_buffers.h"

#include <cstdint>
#include <limits>
#include <utility>

#include "raster/huge_pages.h"

namespace rastray {

namespace {

// Faults in the pages of [data, data + bytes) in one call where the
// kernel can (MADV_POPULATE_WRITE, Linux 5.14), instead of one trap per
// page on first touch (costly on a virtual machine). Only a hint: where it
// is refused the first touch faults them in as before.
void prefaultPages(void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  constexpr uintptr_t kPage = 4096;
  const uintptr_t begin = reinterpret_cast<uintptr_t>(data) & ~(kPage - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes + kPage - 1) & ~(kPage - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE);
#else
  (void)data;
  (void)bytes;
#endif
}

// FlatImage(w, h)'s pixels (transparent black, +inf depth, kNoId), each
// plane's storage advised for huge pages and faulted in at once before it
// is written: a 1920×1080 image is 58 MB, about 14,000 first-touch page
// faults in 4 KiB pages, which took most of a one-shot frame's time on
// this virtual machine. Hints only: the pixels are FlatImage(w, h)'s.
template <typename T>
void fillAdvised(size_t n, const T& value, std::vector<T>* plane) {
  plane->reserve(n);
  const size_t bytes = n * sizeof(T);
  if (bytes >= (size_t(1) << 20)) {
    adviseHugePages(plane->data(), bytes);
    prefaultPages(plane->data(), bytes);
  }
  plane->assign(n, value);
}

FlatImage freshImage(int w, int h) {
  if (w < 0 || h < 0) return FlatImage(w, h);  // its check throws
  FlatImage image;
  image.width = w;
  image.height = h;
  const size_t n = size_t(w) * size_t(h);
  fillAdvised(n, glm::vec4(0.0f), &image.color);
  fillAdvised(n, std::numeric_limits<float>::infinity(), &image.depth);
  fillAdvised(n, kNoId, &image.instance);
  fillAdvised(n, kNoId, &image.triangle);
  return image;
}

}  // namespace

void RasterFrameBuffers::recycle(FlatImage&& image) {
  if (!tryAcquire()) return;
  image_ = std::move(image);
  release();
}

FrameBufferLease::FrameBufferLease(RasterFrameBuffers* pool) {
  if (pool && pool->tryAcquire()) pool_ = pool;
}

FrameBufferLease::~FrameBufferLease() {
  if (pool_) pool_->release();
}

DepthTarget& FrameBufferLease::target(int w, int h, int spp, bool* cleared) {
  if (!pool_) {
    own_ = DepthTarget(w, h, spp);
    *cleared = true;
    return own_;
  }
  DepthTarget& t = pool_->target_;
  const size_t n = size_t(w) * size_t(h) * size_t(spp);
  if (t.keys.size() != n || t.winners.size() != n) {
    // Sized once: the fill below is the only one this size gets.
    t = DepthTarget(w, h, spp);
    *cleared = true;
    return t;
  }
  t.width = w;
  t.height = h;
  t.spp = spp;
  *cleared = false;
  return t;
}

FlatImage FrameBufferLease::image(int w, int h) {
  if (pool_) {
    FlatImage& held = pool_->image_;
    const size_t n = size_t(w) * size_t(h);
    if (held.color.size() == n && held.depth.size() == n && held.instance.size() == n &&
        held.triangle.size() == n) {
      FlatImage image = std::move(held);
      held = FlatImage();
      image.width = w;
      image.height = h;
      image.hasColor = true;
      return image;
    }
  }
  return freshImage(w, h);
}

}  // namespace rastray
