// The explorer page of `rastray serve` (web/explorer.html, .js, .css),
// compiled into the binary by web/embed.cmake: the server reads no files
// for it and the page loads nothing from the network.
#pragma once

#include <string_view>
#include <vector>

namespace rastray {

struct WebAsset {
  const char* path;         // URL path, e.g. "/explorer.js"
  const char* contentType;  // e.g. "text/javascript; charset=utf-8"
  std::string_view bytes;
};

const std::vector<WebAsset>& webAssets();

}  // namespace rastray
