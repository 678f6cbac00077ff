#include "app/serve/serve_server.h"

#include <stdlib.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <sstream>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "app/crossval/crossval.h"
#include "app/crossval/explain.h"
#include "app/serve/serve_api.h"
#include "app/serve/serve_scenes.h"
#include "app/serve/web_assets.h"
#include "common/error.h"
#include "common/image.h"
#include "compare/maps.h"

namespace rastray::serve {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace {

// PNGs are encoded by the same writers `render` and `crossval --report`
// use, which write files: into a private directory, read back, removed.
class ScratchDir {
 public:
  ScratchDir() {
    std::string pattern = (fs::temp_directory_path() / "rastray-serve-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a scratch directory in " + pattern);
    dir_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string png(const std::function<void(const std::string&)>& write) {
    const fs::path path = dir_ / (std::to_string(next_++) + ".png");
    write(path.string());
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    fs::remove(path);
    return bytes.str();
  }

 private:
  fs::path dir_;
  std::atomic<uint64_t> next_{0};
};

// renderReportJson's plain json as the ordered json of the answers.
json ordered(const nlohmann::json& j) { return json::parse(j.dump()); }

void fail(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(message + "\n", "text/plain; charset=utf-8");
}

void sendJson(httplib::Response& res, const json& j) { res.set_content(j.dump(), "application/json"); }

json colorBarJson(const ColorBar& bar) {
  return {{"quantity", bar.quantity},
          {"lo", bar.lo},
          {"hi", bar.hi},
          {"gradient", bar.cssGradient()},
          {"missing", cssColor(bar.missing)}};
}

json visibilityJson(const VisibilityReport& v) {
  json classes = json::object();
  for (int c = 0; c < kMismatchClassCount; ++c)
    classes[toString(MismatchClass(c))] = v.layers.count(MismatchClass(c));
  return {{"compared", v.layers.compared},     {"agreeing", v.layers.agreeing},
          {"agreement", v.layers.agreement()}, {"mismatches", classes},
          {"cutOff", v.layers.cutOff},         {"maxRelativeDepthError", v.depth.maxRelative}};
}

json legendJson() {
  json legend = json::array();
  for (const LegendEntry& e : mismatchLegend())
    legend.push_back({{"key", e.key}, {"label", e.label}, {"color", cssColor(e.srgb)}});
  return legend;
}

// True when the Host header names this machine's loopback interface: a
// page elsewhere that rebinds its DNS name to 127.0.0.1 cannot read the
// scenes through the visitor's browser.
bool isLoopbackHost(const std::string& hostHeader) {
  std::string host = hostHeader;
  if (!host.empty() && host[0] == '[') {
    host = host.substr(0, host.find(']') + 1);
  } else if (const size_t colon = host.rfind(':'); colon != std::string::npos) {
    host = host.substr(0, colon);
  }
  return host == "127.0.0.1" || host == "localhost" || host == "[::1]";
}

}  // namespace

struct ExplorerServer::Impl {
  ServeOptions options;
  SceneAccess access;
  SceneCache cache;
  ScratchDir scratch;
  httplib::Server server;
  // One render at a time: each uses every core (TBB); a second at once
  // would only slow both. Guards `cache` too.
  std::mutex renderMutex;
  std::mutex clientsMutex;
  std::map<std::string, uint64_t> latestSeq;  // per client, the newest request seen
  // Per client, the newest request's render token: a newer request cancels
  // the one rendering (it stops within about a tile per thread).
  std::map<std::string, std::shared_ptr<CancelToken>> renderTokens;

  explicit Impl(const ServeOptions& o) : options(o), access(o.scenes, o.root) { cache.loadBudget = o.memory; }

  // The request's settings under the server's --max-memory: a request may
  // lower the limit, never raise it.
  RenderSettings settingsOf(const RequestParameters& r) const {
    RenderSettings s = renderSettings(r);
    if (options.memory && (!s.isGiven("--max-memory") || s.memory.bytes > options.memory->bytes))
      s.memory = *options.memory;
    return s;
  }

  void routes();
  void frame(const httplib::Request& req, httplib::Response& res, bool pngOnly);
  void explain(const httplib::Request& req, httplib::Response& res);
  void sceneInfo(const httplib::Request& req, httplib::Response& res);
  json mapFrame(const RequestParameters& r, const std::string& path, const RenderSettings& s,
                std::string& png);
  json imageFrame(const RequestParameters& r, const std::string& path, const RenderSettings& s,
                  std::string& png);

  // Records the request; with a client, returns its render token and
  // cancels the token of an older request of the same client (nullptr
  // without a client: nothing can supersede it).
  std::shared_ptr<CancelToken> noteRequest(const RequestParameters& r) {
    if (r.client.empty()) return nullptr;
    std::lock_guard<std::mutex> lock(clientsMutex);
    if (latestSeq.size() > 1024) {  // bounded; forgetting only costs a needless render
      latestSeq.clear();
      renderTokens.clear();
    }
    uint64_t& latest = latestSeq[r.client];
    auto token = std::make_shared<CancelToken>();
    if (r.seq >= latest) {
      std::shared_ptr<CancelToken>& current = renderTokens[r.client];
      if (current && r.seq > latest) current->cancel();
      current = token;
    } else {
      token->cancel();  // already superseded: throwIfSuperseded refuses it
    }
    latest = std::max(latest, r.seq);
    return token;
  }
  // Called with the render lock held: a newer request of the same client
  // arrived while this one waited, so its answer would only be thrown away.
  void throwIfSuperseded(const RequestParameters& r) {
    if (r.client.empty()) return;
    std::lock_guard<std::mutex> lock(clientsMutex);
    const uint64_t latest = latestSeq[r.client];
    if (latest > r.seq) throw HttpError(409, "superseded by request " + std::to_string(latest));
  }
};

namespace {

// Every handler answers errors the same way (serve_server.h).
httplib::Server::Handler guarded(std::function<void(const httplib::Request&, httplib::Response&)> handler) {
  return [handler](const httplib::Request& req, httplib::Response& res) {
    try {
      handler(req, res);
    } catch (const HttpError& e) {
      fail(res, e.status(), e.what());
    } catch (const Cancelled&) {
      fail(res, 409, "superseded by a newer request while rendering");
    } catch (const InputError& e) {
      fail(res, 400, e.what());
    } catch (const std::bad_alloc&) {
      fail(res, 503, "out of memory");
    } catch (const std::exception& e) {
      fail(res, 500, e.what());
    }
  };
}

void refuseParameters(const httplib::Request& req, std::initializer_list<const char*> allowed) {
  for (const auto& [name, value] : req.params)
    if (std::find_if(allowed.begin(), allowed.end(), [&](const char* a) { return name == a; }) ==
        allowed.end())
      throw HttpError(400, "unknown parameter '" + name + "'");
}

}  // namespace

json ExplorerServer::Impl::imageFrame(const RequestParameters& r, const std::string& path,
                                      const RenderSettings& s, std::string& png) {
  const std::shared_ptr<PreparedFrame> prepared = cache.frame(path, r.renderArgs, s);
  // This request's token for this render only: the frame is cached.
  struct TokenScope {
    PreparedFrame& frame;
    TokenScope(PreparedFrame& f, const CancelToken* token) : frame(f) {
      frame.raster.cancel = frame.ray.cancel = token;
    }
    ~TokenScope() { frame.raster.cancel = frame.ray.cancel = nullptr; }
  } scope(*prepared, s.raster.cancel);
  RenderRun run = renderPrepared(*prepared);
  png = r.quickPng ? encodePngQuick(run.output.image)
                   : scratch.png([&](const std::string& file) { writePng(file, run.output.image); });
  json work = ordered(renderReportJson(*prepared->scene, s, run));
  // The encoded image's storage serves this frame's next preview.
  prepared->buffers->recycle(std::move(run.output.image));
  // Where the BVH came from: none (the rasterizer alone), built by this
  // request, or kept from an earlier one (the same frame, or another frame
  // over the same rebased scene and culling mode).
  work["preparation"] = s.renderer == RendererKind::Raster        ? "none"
                        : prepared->builtBvh && !prepared->reused ? "built"
                                                                  : "reused";
  return {{"renders", json::array({work})}};
}

json ExplorerServer::Impl::mapFrame(const RequestParameters& r, const std::string& path,
                                    const RenderSettings& s, std::string& png) {
  const std::shared_ptr<const CrossvalResult> cv = cache.crossval(path, r.renderArgs, s);
  const bool hybrid = r.pair == "hybrid";
  const VisibilityReport& visibility = hybrid ? cv->hybridVsRay : cv->rasterVsRay;
  const FlatImage& image = (hybrid ? cv->hybrid : cv->raster).output.image;
  json j;
  png = scratch.png([&](const std::string& file) {
    if (r.view == View::Mismatch) {
      writeMismatchMap(file, visibility);
      j["legend"] = legendJson();
    } else if (r.view == View::DepthDiff) {
      j["colorBar"] = colorBarJson(writeDepthDifferenceMap(file, visibility));
    } else {
      j["colorBar"] = colorBarJson(writeDifferenceHeatMap(file, image, cv->raytrace.output.image));
    }
  });
  const ColorMetrics& color = hybrid ? cv->hybridVsRayColor : cv->rasterVsRayColor;
  j["comparison"] = {{"pair", {hybrid ? "hybrid" : "raster", "raytrace"}},
                     {"visibility", visibilityJson(visibility)},
                     {"color",
                      {{"rms", color.rmsError},
                       {"psnr", std::isinf(color.psnr) ? -1.0 : color.psnr},
                       {"max", color.maxError}}}};
  json renders = json::array();
  const Scene& scene = *cache.prepared(path, s);
  for (const auto& [kind, run] :
       {std::pair{RendererKind::Raster, &cv->raster}, std::pair{RendererKind::Raytrace, &cv->raytrace},
        std::pair{RendererKind::Hybrid, &cv->hybrid}}) {
    RenderSettings named = s;
    named.renderer = kind;
    renders.push_back(ordered(renderReportJson(scene, named, *run)));
  }
  j["renders"] = renders;
  return j;
}

void ExplorerServer::Impl::frame(const httplib::Request& req, httplib::Response& res, bool pngOnly) {
  const RequestParameters r = parseRequest(req.params, Endpoint::Frame);
  const std::string path = access.resolve(r.scene);
  RenderSettings settings = settingsOf(r);
  const std::shared_ptr<CancelToken> token = noteRequest(r);
  settings.raster.cancel = settings.ray.cancel = token.get();
  std::lock_guard<std::mutex> lock(renderMutex);
  throwIfSuperseded(r);
  std::string png;
  json j = {
      {"schema", "rastray.serve.frame"}, {"version", 1}, {"scene", r.scene}, {"view", toString(r.view)}};
  j["size"] = {settings.camera.width(), settings.camera.height()};
  j["command"] = commandLine(r, Endpoint::Frame);
  j.update(r.view == View::Image ? imageFrame(r, path, settings, png) : mapFrame(r, path, settings, png));
  if (pngOnly) {
    res.set_content(png, "image/png");
    return;
  }
  j["image"] = "data:image/png;base64," + base64(png);
  sendJson(res, j);
}

void ExplorerServer::Impl::explain(const httplib::Request& req, httplib::Response& res) {
  const RequestParameters r = parseRequest(req.params, Endpoint::Explain);
  const std::string path = access.resolve(r.scene);
  RenderSettings settings = settingsOf(r);
  const int width = settings.camera.width(), height = settings.camera.height();
  if (r.x >= width || r.y >= height)
    throw HttpError(400, "x, y: pixel (" + std::to_string(r.x) + ", " + std::to_string(r.y) +
                             ") lies outside the " + std::to_string(width) + "x" + std::to_string(height) +
                             " image");
  const std::shared_ptr<CancelToken> token = noteRequest(r);
  settings.raster.cancel = settings.ray.cancel = token.get();
  std::lock_guard<std::mutex> lock(renderMutex);
  throwIfSuperseded(r);
  const std::shared_ptr<const Scene> scene = cache.prepared(path, settings);
  const PixelExplanation e = explainPixel(*scene, settings, r.x, r.y);
  // The camera explain traced with: the same scene, overrides and size.
  const Camera camera = makeCamera(*scene, settings.camera.overrides(), width, height);
  const double size = scene->bounds.empty() ? 1.0 : glm::length(scene->bounds.hi - scene->bounds.lo);
  sendJson(res, {{"schema", "rastray.serve.explain"},
                 {"version", 1},
                 {"command", commandLine(r, Endpoint::Explain)},
                 {"explain", explanationJson(e)},
                 {"text", explanationText(e)},
                 {"rays", rayOverlayJson(camera, e.rayEvents, size)}});
}

void ExplorerServer::Impl::sceneInfo(const httplib::Request& req, httplib::Response& res) {
  refuseParameters(req, {"scene", "size"});
  RequestParameters r;
  r.scene = req.has_param("scene") ? req.get_param_value("scene") : "";
  if (r.scene.empty()) throw HttpError(400, "scene: missing (one of /api/scenes)");
  // The size is checked by the render command's own parser.
  QueryParameters query = {{"scene", r.scene}};
  if (req.has_param("size")) query.emplace("size", req.get_param_value("size"));
  const RenderSettings settings = settingsOf(parseRequest(query, Endpoint::Frame));
  const std::string path = access.resolve(r.scene);
  std::lock_guard<std::mutex> lock(renderMutex);
  json j = sceneInfoJson(*cache.loaded(path), settings.camera.width(), settings.camera.height());
  j["scene"] = r.scene;
  sendJson(res, j);
}

void ExplorerServer::Impl::routes() {
  const bool loopback = options.host == "127.0.0.1" || options.host == "localhost" || options.host == "::1";
  server.set_pre_routing_handler([loopback](const httplib::Request& req, httplib::Response& res) {
    if (loopback && !isLoopbackHost(req.get_header_value("Host"))) {
      fail(res, 403, "this server answers requests for 127.0.0.1 or localhost only");
      return httplib::Server::HandlerResponse::Handled;
    }
    // The page loads nothing from elsewhere; say so to the browser too.
    res.set_header("Content-Security-Policy",
                   "default-src 'self'; img-src 'self' data:; connect-src 'self'; frame-ancestors 'none'");
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("Cache-Control", "no-store");
    return httplib::Server::HandlerResponse::Unhandled;
  });
  for (const WebAsset& asset : webAssets()) {
    std::string pattern;
    for (const char c : std::string(asset.path)) pattern += c == '.' ? std::string("\\.") : std::string(1, c);
    auto serveAsset = [asset](const httplib::Request&, httplib::Response& res) {
      res.set_content(std::string(asset.bytes), asset.contentType);
    };
    server.Get(pattern, serveAsset);
    if (std::string(asset.path) == "/explorer.html") server.Get("/", serveAsset);
  }
  server.Get("/api/options", guarded([](const httplib::Request& req, httplib::Response& res) {
               refuseParameters(req, {});
               sendJson(res, optionTableJson());
             }));
  server.Get("/api/scenes", guarded([this](const httplib::Request& req, httplib::Response& res) {
               refuseParameters(req, {});
               sendJson(res, {{"schema", "rastray.serve.scenes"}, {"version", 1}, {"scenes", access.list()}});
             }));
  server.Get("/api/scene",
             guarded([this](const httplib::Request& q, httplib::Response& s) { sceneInfo(q, s); }));
  server.Get("/api/frame",
             guarded([this](const httplib::Request& q, httplib::Response& s) { frame(q, s, false); }));
  server.Get("/api/image",
             guarded([this](const httplib::Request& q, httplib::Response& s) { frame(q, s, true); }));
  server.Get("/api/explain",
             guarded([this](const httplib::Request& q, httplib::Response& s) { explain(q, s); }));
  server.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (res.body.empty()) fail(res, res.status, res.status == 404 ? "not found" : "request refused");
  });
}

ExplorerServer::ExplorerServer(const ServeOptions& options) : impl_(std::make_unique<Impl>(options)) {
  impl_->routes();
}

ExplorerServer::~ExplorerServer() = default;

int ExplorerServer::bind() {
  const ServeOptions& o = impl_->options;
  const int port = o.port == 0                                  ? impl_->server.bind_to_any_port(o.host)
                   : impl_->server.bind_to_port(o.host, o.port) ? o.port
                                                                : -1;
  if (port < 0)
    throw InputError(
        "command line", "--port",
        "cannot listen on " + o.host + ":" + std::to_string(o.port) + " (in use, or no such address)");
  return port;
}

bool ExplorerServer::run() { return impl_->server.listen_after_bind(); }

void ExplorerServer::stop() { impl_->server.stop(); }

}  // namespace rastray::serve
