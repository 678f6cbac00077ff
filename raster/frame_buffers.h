// Frame-sized buffers kept between frames for a caller that renders frame
// after frame (rastray bench, an explorer's previews): the depth target and
// the image's storage. Without it every frame allocates and fills about
// 73 MB at 1920×1080, 1 spp (16 MB depth target, 57 MB image) before the
// tiles write the same memory again; with it a tile clears its own part of
// the target while it is in cache, and the image is not filled at all. The
// triangle setups' storage is kept too (its capacity: about 235 MB for the
// 10^6-triangle terrain at 1080p), so a frame does not fault in and zero
// fresh pages for them; the peak is the same, held between frames.
//
// RasterOptions::frameBuffers points at one; renderRaster takes what fits
// and the caller hands each finished image back with recycle(). A frame
// that finds the pool in use by another frame allocates its own buffers,
// so one pool shared by concurrent frames is safe, only not faster.
// Invariants the renderer keeps with reused (stale) storage: every tile
// clears its own rectangle of the depth target before its depth pass, and
// the resolve writes every pixel's colour, depth and ids, so no frame sees
// another frame's values (tests/raster/frame_buffers_test.cpp).
#pragma once

#include <atomic>
#include <vector>

#include "common/image.h"
#include "raster/coverage.h"
#include "raster/setup.h"

namespace rastray {

class RasterFrameBuffers {
 public:
  // Hands a finished frame's image back; its storage serves the next frame
  // of the same size. Anything else held is dropped (and so is `image`
  // while a frame is using the pool).
  void recycle(FlatImage&& image);

 private:
  friend class FrameBufferLease;
  bool tryAcquire() {
    bool expected = false;
    return inUse_.compare_exchange_strong(expected, true, std::memory_order_acquire);
  }
  void release() { inUse_.store(false, std::memory_order_release); }

  std::atomic<bool> inUse_{false};  // a flag, not a mutex: the same thread may ask twice
  DepthTarget target_;
  FlatImage image_;
  std::vector<TriangleSetup> setups_;
  RefinePlanes planes_;
};

// One frame's use of a pool (raster/rasterizer.cpp): takes the buffers for
// the frame if the pool is free, else the frame allocates its own.
class FrameBufferLease {
 public:
  explicit FrameBufferLease(RasterFrameBuffers* pool);
  ~FrameBufferLease();
  FrameBufferLease(const FrameBufferLease&) = delete;
  FrameBufferLease& operator=(const FrameBufferLease&) = delete;

  // A w × h × spp depth target. Its contents are unspecified when it came
  // from the pool (`*cleared` false): each tile must clear its rectangle.
  DepthTarget& target(int w, int h, int spp, bool* cleared);
  // A w × h image, hasColor set; contents unspecified when reused: the
  // resolve must write every pixel.
  FlatImage image(int w, int h);
  // Storage for the frame's triangle setups (prepareTriangles' `setups`):
  // the pool's, kept with its capacity between frames, else the lease's own.
  std::vector<TriangleSetup>& setups() { return pool_ ? pool_->setups_ : ownSetups_; }
  // The same for their refinement planes (prepareTriangles' RefinePlaneRequest).
  RefinePlanes& planes() { return pool_ ? pool_->planes_ : ownPlanes_; }

 private:
  RasterFrameBuffers* pool_ = nullptr;  // null: not leased (no pool, or busy)
  DepthTarget own_;
  std::vector<TriangleSetup> ownSetups_;
  RefinePlanes ownPlanes_;
};

}  // namespace rastray
