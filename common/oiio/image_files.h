// The module's image files (common/oiio/image_files.cpp): common/image.h's
// writers and readers, done with OpenImageIO. See common/oiio_module.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/image.h"

namespace rastray::oiio {

void writeRgba8Png(const std::string& path, const std::string& tmp, int width, int height,
                   const uint8_t* rgba);
// writeRgba8Png's image (the same pixels and attributes) in memory, quickly
// compressed: no row filter, zlib level 1.
std::vector<unsigned char> encodeRgba8PngQuick(int width, int height, const uint8_t* rgba);
void writeExr(const std::string& path, const std::string& tmp, const FlatImage& image,
              ColorPrecision precision);
void writeDeepExr(const std::string& path, const std::string& tmp, const DeepImage& image);
bool isDeepExr(const std::string& path, uint64_t maxBytes);
std::string exrChannelType(const std::string& path, const std::string& channel);
FlatImage readExr(const std::string& path, uint64_t maxBytes);
DeepImage readDeepExr(const std::string& path, uint64_t maxBytes);

}  // namespace rastray::oiio
