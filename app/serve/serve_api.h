// The explorer's HTTP parameters (`rastray serve`): checked, turned into
// the argument list `rastray render`, `crossval` or `explain` would take,
// and parsed by the same code as those commands (so a request meets the
// CLI's limits and messages word for word); plus the JSON pieces the page
// reads that the commands have no form for (the option table, the ray tree
// projected onto the image, the equivalent command line).
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/engine/render_setup.h"
#include "common/camera.h"
#include "common/trace.h"

namespace rastray::serve {

// A request the server refuses, with the HTTP status (400: bad or unknown
// parameter; 403: a path outside what the server may open; 404: no such
// scene; 409: superseded by a newer request of the same client).
class HttpError : public std::runtime_error {
 public:
  HttpError(int status, const std::string& message) : std::runtime_error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

// What the page shows from one set of render settings.
enum class View {
  Image,      // one renderer's image (`rastray render`)
  Mismatch,   // visibility-mismatch map by class (`rastray crossval` report)
  DepthDiff,  // |ΔZ| heat map on agreeing hits
  ColorDiff,  // colour-difference heat map
};
const char* toString(View view);

// The endpoints that take render settings.
enum class Endpoint { Frame, Explain };

// A request's parameters, checked for shape (names, counts, numbers) but
// not yet for the render commands' limits: renderSettings() does that.
struct RequestParameters {
  Endpoint endpoint = Endpoint::Frame;
  std::string scene;  // as the page names it (/api/scenes)
  View view = View::Image;
  // The renderer compared with the ray caster in the maps: raster or hybrid.
  std::string pair = "raster";
  // The render options as command-line tokens, in the render-option
  // table's order, "--renderer R" first for the image view.
  std::vector<std::string> renderArgs;
  int x = -1, y = -1;  // the pixel explained (Endpoint::Explain)
  // png=quick (image view): the PNG compressed for speed, not size
  // (encodePngQuick: the same pixels); the explorer's previews ask for it.
  bool quickPng = false;
  // Supersession: a later seq of the same client makes this one obsolete.
  std::string client;
  uint64_t seq = 0;

  // Image view: one renderer; the maps and explain run every renderer
  // (their settings are those of crossval and explain).
  bool allRenderers() const { return endpoint == Endpoint::Explain || view != View::Image; }
};

using QueryParameters = std::multimap<std::string, std::string>;

// Checks names and shapes. Render options are named as on the command
// line without the dashes ("spp", "shadow-map-size"); several values are
// joined by commas ("size=320,240"); flags take on or off. Unknown names,
// repeated names, a value count that does not fit the option, and options
// the server sets itself (threads, debug-pixel: explain picks the pixel)
// throw HttpError 400 with a message naming the parameter.
RequestParameters parseRequest(const QueryParameters& query, Endpoint endpoint);

// The render settings the parameters give, parsed and checked exactly as
// the render command (image view) or crossval/explain (maps, explain) parse
// them; a refusal throws HttpError 400 with the command's own message.
RenderSettings renderSettings(const RequestParameters& request);

// The equivalent command line, shell-quoted, ready to copy:
// `rastray render SCENE ... -o render.png` for the image view, `rastray
// crossval SCENE ... --report report` for the maps, `rastray explain SCENE
// X Y ...` for explain.
std::string commandLine(const RequestParameters& request, Endpoint endpoint);
std::string shellQuote(const std::string& word);

// The render options the page may send: name, value count (0: a flag),
// the renderers and condition under which each applies, the CLI's help and
// default (schema rastray.serve.options).
nlohmann::ordered_json optionTableJson();

// The ray caster's ray tree of one pixel (the TraceStage::Ray events
// explain records) as 2-D segments in image pixels, for drawing over the
// image: per ray its sample, kind, depth, outcome and the projected
// segment from its origin to its hit (or to the end of its range, a far
// point standing in for an infinite one), clipped to the near plane.
// Rays wholly behind the camera are left out. `camera` must be the one
// the rays were traced with (same rebased scene, same size).
nlohmann::ordered_json rayOverlayJson(const Camera& camera, const std::vector<TraceEvent>& events,
                                      double sceneSize);

// RFC 4648 base64, for the PNG data URL of /api/frame.
std::string base64(const std::string& bytes);

}  // namespace rastray::serve
