// A check of an OpenEXR file's headers before OpenImageIO and OpenEXR
// read it (common/image.cpp's readers): those libraries trust sizes and
// types that a damaged or hostile file can set to anything.
#pragma once

#include <cstdint>
#include <string>

namespace rastray {

// Walks the headers (OpenEXR file layout: magic number, version and flags,
// then per part a list of attributes "name\0 type\0 int32 size, value"
// ended by an empty name; a multi-part file ends its list of headers with
// one more empty name). Throws InputError(path, "" or "header", ...) for a
// file that is missing, not OpenEXR, truncated inside its headers, has an
// attribute whose declared size runs past the end of the file or differs
// from what OpenEXR will read for its type, a channel list ("chlist") with
// a pixel type other than uint, half, float, or a preview whose size is
// not its width x height pixels.
// What it does not look at (pixel data, the offset table, attribute values
// other than channel lists) is left to OpenEXR.
// What the walk learnt about the first part, so a caller can refuse a
// huge data window before OpenEXR allocates tables for it.
struct ExrHeaderFacts {
  uint64_t fileSize = 0;
  uint64_t dataPixels = 0;  // 0: no valid dataWindow (OpenEXR then refuses the file)
  bool deep = false;        // the "non-image" flag, or a part type "deepscanline"/"deeptile"
  uint64_t tilePixels = 0;  // x size times y size of a tiled part's tiles; 0: scan lines
};
ExrHeaderFacts checkExrHeaders(const std::string& path);

}  // namespace rastray
