#include "raster/frame_buffers.h"

#include <utility>

namespace rastray {

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
  return FlatImage(w, h);
}

}  // namespace rastray
