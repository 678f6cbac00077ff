// `rastray serve`: the explorer's HTTP endpoints, with the server running in
// this process on a free port (app/serve/serve_server.h).
#ifdef RASTRAY_HAVE_RENDERERS

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <httplib.h>
#include <stb/stb_image.h>
#include <nlohmann/json.hpp>

#include "app/serve/serve_api.h"
#include "app/serve/serve_scenes.h"
#include "app/serve/serve_server.h"
#include "run_command.h"
#include "tests/test_files.h"

namespace rastray {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string scenePath(const char* name) { return std::string(RASTRAY_SCENES) + "/" + name + ".gltf"; }

using test::slurp;

// Width and height from a PNG's IHDR chunk (big-endian, bytes 16-23).
std::pair<int, int> pngSize(const std::string& png) {
  EXPECT_GE(png.size(), 24u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  auto u32 = [&](size_t at) {
    uint32_t v = 0;
    for (size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(png[at + i]);
    return int(v);
  };
  return {u32(16), u32(20)};
}

// Splits the shell words shellQuote writes: plain words and '...' quoting.
std::vector<std::string> shellWords(const std::string& line) {
  std::vector<std::string> words;
  std::string word;
  bool inWord = false, quoted = false, escaped = false;
  for (const char c : line) {
    if (escaped) {
      word += c;  // the character after a backslash, outside quotes
      escaped = false;
    } else if (quoted) {
      if (c == '\'')
        quoted = false;
      else
        word += c;
    } else if (c == '\'') {
      quoted = inWord = true;
    } else if (c == '\\') {
      escaped = inWord = true;
    } else if (c == ' ') {
      if (inWord) words.push_back(word);
      word.clear();
      inWord = false;
    } else {
      word += c;
      inWord = true;
    }
  }
  if (inWord) words.push_back(word);
  return words;
}

// A root directory with one scene inside, one beside it (outside), and a
// link from inside to the outside one.
class ServeTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    base_ = test::scratchDir();  // the suite's own, while no test runs
    fs::create_directories(base_ / "root" / "sub");
    fs::copy_file(scenePath("three-triangles"), base_ / "root" / "sub" / "three-triangles.gltf");
    fs::copy_file(scenePath("three-triangles"), base_ / "secret.gltf");
    fs::create_symlink(base_ / "secret.gltf", base_ / "root" / "escape.gltf");
    serve::ServeOptions options;
    options.scenes = {scenePath("cornell-box")};
    options.root = (base_ / "root").string();
    options.port = 0;
    server_ = new serve::ExplorerServer(options);
    port_ = server_->bind();
    thread_ = std::thread([] { server_->run(); });
  }
  static void TearDownTestSuite() {
    server_->stop();
    thread_.join();
    delete server_;
  }

  static httplib::Result get(const std::string& target, const std::string& host = "127.0.0.1") {
    httplib::Client client("127.0.0.1", port_);
    client.set_read_timeout(120, 0);
    return client.Get(target.c_str(), {{"Host", host}});
  }
  static std::string cornell() {
    return "scene=" + httplib::detail::encode_query_param(scenePath("cornell-box"));
  }

  static inline fs::path base_;
  static inline serve::ExplorerServer* server_ = nullptr;
  static inline int port_ = 0;
  static inline std::thread thread_;
};

TEST_F(ServeTest, PageAndItsFilesAreServedWithoutNetworkResources) {
  const auto page = get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<script src=\"/explorer.js\">"), std::string::npos);
  // No URL but the SVG namespace's name (which is never fetched).
  auto urls = [](std::string text) {
    const std::string svg = "http://www.w3.org/2000/svg";
    for (size_t at; (at = text.find(svg)) != std::string::npos;) text.erase(at, svg.size());
    return text.find("http://") != std::string::npos || text.find("https://") != std::string::npos;
  };
  EXPECT_FALSE(urls(page->body));
  for (const char* path : {"/explorer.js", "/explorer.css"}) {
    const auto r = get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 200) << path;
    EXPECT_FALSE(urls(r->body)) << path;
  }
  EXPECT_NE(page->get_header_value("Content-Security-Policy").find("default-src 'self'"), std::string::npos);
}

TEST_F(ServeTest, RenderReturnsPngOfTheAskedSize) {
  for (const char* renderer : {"raster", "raytrace", "hybrid"}) {
    const auto r = get("/api/image?" + cornell() + "&size=96,72&spp=4&renderer=" + renderer);
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200) << r->body;
    EXPECT_EQ(r->get_header_value("Content-Type"), "image/png");
    EXPECT_EQ(pngSize(r->body), std::make_pair(96, 72)) << renderer;
  }
  const auto frame = get("/api/frame?" + cornell() + "&size=64,48&renderer=hybrid");
  ASSERT_TRUE(frame);
  ASSERT_EQ(frame->status, 200) << frame->body;
  const json j = json::parse(frame->body);
  EXPECT_EQ(j["schema"], "rastray.serve.frame");
  EXPECT_EQ(j["size"], json::array({64, 48}));
  EXPECT_EQ(j["image"].get<std::string>().rfind("data:image/png;base64,iVBORw0KGgo", 0), 0u);
  // The work of the render: what `render --json` reports.
  const json& work = j["renders"][0];
  EXPECT_EQ(work["renderer"], "hybrid");
  EXPECT_GT(work["counters"]["rays.shadow"].get<uint64_t>(), 0u);
  EXPECT_FALSE(work["passesLeftOut"].empty());
  EXPECT_TRUE(work["timings"].contains("raster.tiles"));
}

TEST_F(ServeTest, PreparedRendererIsKeptBetweenRequests) {
  const std::string target = "/api/frame?" + cornell() + "&size=40,30&renderer=raytrace&cull=back";
  const auto first = get(target), second = get(target);
  ASSERT_TRUE(first && second);
  ASSERT_EQ(first->status, 200) << first->body;
  const json a = json::parse(first->body), b = json::parse(second->body);
  EXPECT_EQ(a["renders"][0]["preparation"], "built");
  EXPECT_TRUE(a["renders"][0]["timings"].contains("raytrace.bvh_build"));
  EXPECT_EQ(b["renders"][0]["preparation"], "reused");
  EXPECT_FALSE(b["renders"][0]["timings"].contains("raytrace.bvh_build"));
  EXPECT_EQ(a["image"], b["image"]);
}

// A prepared raster frame keeps its depth target and image storage
// between requests (PreparedFrame::buffers): the next request renders into
// the last one's stale storage and must give the same picture, at 1 and 4
// samples per pixel and at a size that is no multiple of the tile.
TEST_F(ServeTest, RasterPreviewsReuseTheirBuffersAndKeepThePicture) {
  for (const char* spp : {"1", "4"}) {
    const std::string target = "/api/frame?" + cornell() + "&size=130,67&renderer=raster&spp=" + spp;
    const auto first = get(target), second = get(target), third = get(target);
    ASSERT_TRUE(first && second && third);
    ASSERT_EQ(first->status, 200) << first->body;
    const json a = json::parse(first->body), b = json::parse(second->body), c = json::parse(third->body);
    EXPECT_EQ(a["image"], b["image"]) << spp;
    EXPECT_EQ(a["image"], c["image"]) << spp;
  }
}

// Decoded RGBA bytes of a PNG (stb_image), empty when it does not decode.
std::vector<unsigned char> pngPixels(const std::string& png) {
  int w = 0, h = 0, n = 0;
  unsigned char* p = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(png.data()),
                                           int(png.size()), &w, &h, &n, 4);
  if (!p) return {};
  std::vector<unsigned char> out(p, p + size_t(w) * size_t(h) * 4);
  stbi_image_free(p);
  return out;
}

// The previews' png=quick: the same pixels as the command line's PNG,
// other bytes (no row filter, zlib level 1), and in the JSON frame too;
// frames of other cameras share one buffer pool, so previews after an
// orbit step render into the last camera's stale storage and keep their
// picture. png takes quick or small, and only in the image view.
TEST_F(ServeTest, QuickPreviewPngsHoldTheCommandLinesPixels) {
  const std::vector<std::string> cameras = {"&eye=0.3,0.9,3.4&target=0,0.9,0&up=0,1,0",
                                            "&eye=-0.4,1.1,3.3&target=0,0.9,0&up=0,1,0", ""};
  for (const char* spp : {"1", "4"})
    for (const std::string& camera : cameras) {
      const std::string settings = cornell() + "&size=131,67&renderer=raster&spp=" + spp + camera;
      const auto small = get("/api/image?" + settings);
      const auto quick = get("/api/image?" + settings + "&png=quick");
      const auto frame = get("/api/frame?" + settings + "&png=quick");
      ASSERT_TRUE(small && quick && frame);
      ASSERT_EQ(quick->status, 200) << quick->body;
      EXPECT_EQ(quick->get_header_value("Content-Type"), "image/png");
      EXPECT_NE(quick->body, small->body) << "png=quick encodes otherwise";
      const std::vector<unsigned char> pixels = pngPixels(small->body);
      ASSERT_EQ(pixels.size(), size_t(131 * 67 * 4));
      EXPECT_TRUE(pngPixels(quick->body) == pixels) << spp << camera;
      EXPECT_EQ(json::parse(frame->body)["image"], "data:image/png;base64," + serve::base64(quick->body));
    }
  const auto bad = get("/api/image?" + cornell() + "&size=40,30&png=fast");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_NE(bad->body.find("png: 'fast' is not one of quick, small"), std::string::npos) << bad->body;
  const auto map = get("/api/frame?" + cornell() + "&size=40,30&view=mismatch&png=quick");
  ASSERT_TRUE(map);
  EXPECT_EQ(map->status, 400) << map->body;
}

// Every prepared frame renders into the cache's one buffer pool: an orbit
// prepares a frame per camera, and a pool per frame allocated a fresh
// image (and the kernel zeroed its pages) for every preview.
TEST(ServeSceneCache, FramesOfEveryCameraShareOneBufferPool) {
  serve::SceneCache cache;
  const std::string path = scenePath("cornell-box");
  std::vector<std::shared_ptr<serve::PreparedFrame>> frames;
  for (const char* eye : {"0.3,0.9,3.4", "-0.4,1.1,3.3"}) {
    serve::QueryParameters q = {{"scene", path}, {"size", "40x30"}, {"eye", eye}};
    const serve::RequestParameters r = serve::parseRequest(q, serve::Endpoint::Frame);
    frames.push_back(cache.frame(path, r.renderArgs, serve::renderSettings(r)));
  }
  ASSERT_NE(frames[0], frames[1]);
  ASSERT_NE(frames[0]->buffers, nullptr);
  EXPECT_EQ(frames[0]->buffers, frames[1]->buffers);
  EXPECT_EQ(frames[0]->raster.frameBuffers, frames[0]->buffers);
  EXPECT_EQ(frames[1]->raster.frameBuffers, frames[1]->buffers);
}

// The BVH depends on the rebased scene and the culling mode only: changing
// spp or the shadow method keeps it, and so does moving the camera under
// --origin world; moving the eye under --origin camera (the default)
// rebases the scene and builds another. Every image is the command line's.
TEST_F(ServeTest, TheBvhIsSharedAcrossOptionsAndWorldOriginCameras) {
  // cull=front: a BVH no other test of this server's suite has built.
  const std::string options = "&size=40,30&renderer=hybrid&cull=front";
  const std::string base = "/api/frame?" + cornell() + options;
  auto work = [&](const std::string& extra) {
    const auto r = get(base + extra);
    EXPECT_TRUE(r && r->status == 200) << extra << ": " << (r ? r->body : "no response");
    return r && r->status == 200 ? json::parse(r->body) : json();
  };
  auto preparation = [](const json& j) { return j["renders"][0]["preparation"].get<std::string>(); };
  const json first = work("&shadows=map");
  EXPECT_EQ(preparation(first), "built");
  EXPECT_TRUE(first["renders"][0]["timings"].contains("raytrace.bvh_build"));
  for (const std::string extra : {"&shadows=rays", "&shadows=rays&spp=4", "&max-depth=1"}) {
    const json j = work(extra);
    EXPECT_EQ(preparation(j), "reused") << extra;
    EXPECT_FALSE(j["renders"][0]["timings"].contains("raytrace.bvh_build")) << extra;
    // The same image as the command line the page shows.
    const auto words = shellWords(j["command"].get<std::string>());
    std::vector<std::string> args(words.begin() + 1, words.end());
    const std::string out = (base_ / "shared.png").string();
    for (size_t i = 0; i + 1 < args.size(); ++i)
      if (args[i] == "-o") args[i + 1] = out;
    const auto run = test::runRastray(args);
    ASSERT_EQ(run.status, 0) << run.err;
    const auto image = get("/api/image?" + cornell() + options + extra);
    EXPECT_EQ(image->body, slurp(out)) << extra;
  }
  // The frame that built the caster renders its own camera and options
  // again after the others have bound theirs.
  EXPECT_EQ(work("&shadows=map")["image"], first["image"]);
  EXPECT_EQ(preparation(work("&origin=world&eye=0,0,3.5")), "built");
  EXPECT_EQ(preparation(work("&origin=world&eye=0.5,0.2,3.4")), "reused");
  EXPECT_EQ(preparation(work("&eye=0.5,0.2,3.4")), "built");
  const auto raster = get("/api/frame?" + cornell() + "&size=40,30&renderer=raster");
  ASSERT_TRUE(raster && raster->status == 200);
  EXPECT_EQ(preparation(json::parse(raster->body)), "none");
}

TEST_F(ServeTest, MapsComeFromCrossvalAndMatchItsReport) {
  const std::string settings = "&size=48,36&spp=4&shadow-map-size=256";
  for (const char* view : {"mismatch", "depth-diff", "color-diff"}) {
    const auto r = get("/api/frame?" + cornell() + settings + "&view=" + view);
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200) << r->body;
    const json j = json::parse(r->body);
    EXPECT_EQ(j["renders"].size(), 3u) << view;
    EXPECT_EQ(j["comparison"]["visibility"]["compared"].get<uint64_t>(), 48u * 36u * 4u) << view;
    EXPECT_TRUE(j.contains(std::string(view) == "mismatch" ? "legend" : "colorBar")) << view;
    EXPECT_EQ(j["command"].get<std::string>().rfind("rastray crossval ", 0), 0u) << view;
  }
  // The same pictures as `rastray crossval --report` writes.
  const fs::path report = base_ / "report";
  auto words =
      shellWords(json::parse(get("/api/frame?" + cornell() + settings + "&view=mismatch")->body)["command"]);
  ASSERT_EQ(words.back(), "report");
  words.back() = report.string();
  const auto run = test::runRastray(std::vector<std::string>(words.begin() + 1, words.end()));
  ASSERT_EQ(run.status, 0) << run.err;
  for (const auto& [view, file] :
       {std::pair{"mismatch", "mismatch.png"}, std::pair{"depth-diff", "depth-diff.png"},
        std::pair{"color-diff", "color-diff.png"}}) {
    const auto r = get("/api/image?" + cornell() + settings + "&view=" + view);
    EXPECT_EQ(r->body, slurp(report / "cornell-box" / file)) << view;
  }
}

TEST_F(ServeTest, ExplainReturnsTheExplanationAndTheRayTreeOnTheImage) {
  const auto r = get("/api/explain?" + cornell() + "&size=80,60&spp=4&x=50&y=30");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json j = json::parse(r->body);
  EXPECT_EQ(j["schema"], "rastray.serve.explain");
  EXPECT_EQ(j["command"].get<std::string>().find("rastray explain "), 0u);
  const json& e = j["explain"];
  EXPECT_EQ(e["schema"], "rastray.explain");
  EXPECT_EQ(e["pixel"], json::array({50, 30}));
  ASSERT_EQ(e["samples"].size(), 4u);
  for (const json& sample : e["samples"]) {
    ASSERT_FALSE(sample["layers"].empty());
    EXPECT_TRUE(sample["layers"][0].contains("verdict"));
    EXPECT_FALSE(sample["layers"][0]["raytrace"].is_null());
  }
  EXPECT_FALSE(e["raster"]["events"].empty());
  EXPECT_NE(j["text"].get<std::string>().find("== hits per sample"), std::string::npos);
  // The ray tree projected onto the image: each primary ray's hit lands on
  // its sample's position, and each sample has a shadow ray towards the light.
  int primaries = 0, shadows = 0;
  for (const json& ray : j["rays"]) {
    if (ray["kind"] == "shadow") ++shadows;
    if (ray["kind"] != "primary") continue;
    ++primaries;
    const json& position = e["samples"][ray["sample"].get<size_t>()]["position"];
    EXPECT_NEAR(ray["to"][0].get<double>(), position[0].get<double>(), 1e-4);
    EXPECT_NEAR(ray["to"][1].get<double>(), position[1].get<double>(), 1e-4);
  }
  EXPECT_EQ(primaries, 4);
  EXPECT_GE(shadows, 4);

  // The same explanation as the command line gives.
  auto words = shellWords(j["command"]);
  words.push_back("--json");
  const auto run = test::runRastray(std::vector<std::string>(words.begin() + 1, words.end()));
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_EQ(json::parse(run.out)["samples"], e["samples"]);
}

TEST_F(ServeTest, BadParametersGet400WithTheCommandsMessage) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"/api/image?" + cornell() + "&spp=9", "spp: 9 is not supported"},
      {"/api/image?" + cornell() + "&spp=abc", "spp: 'abc' is not an integer"},
      {"/api/image?" + cornell() + "&size=0,10", "size: '0' is not in [1, 16384]"},
      {"/api/image?" + cornell() + "&size=20000,10", "size: '20000' is not in [1, 16384]"},
      {"/api/image?" + cornell() + "&size=10", "size: '10': needs 2 values"},
      {"/api/image?" + cornell() + "&max-depth=65&renderer=raytrace", "max-depth: '65' is not in [0, 64]"},
      {"/api/image?" + cornell() + "&renderer=vulkan", "renderer: 'vulkan' is not one of"},
      {"/api/image?" + cornell() + "&renderer=raytrace&shadow-map-size=512",
       "shadow-map-size: applies to raster"},
      {"/api/image?" + cornell() + "&transparency=peel:0", "transparency: peel layer count"},
      {"/api/image?" + cornell() + "&wireframe=yes", "wireframe: 'yes': a flag takes on or off"},
      {"/api/image?" + cornell() + "&spp=4&spp=8", "spp: given more than once"},
      {"/api/image?" + cornell() + "&view=depth", "view: 'depth' is not one of"},
      {"/api/image?" + cornell() + "&view=mismatch&renderer=raster",
       "renderer: the mismatch view runs every"},
      {"/api/image?size=10,10", "scene: missing"},
      {"/api/image?" + cornell() + "&max-memory=100K", "above the memory limit of 100.0 KiB"},
      {"/api/image?" + cornell() + "&view=color-diff&max-memory=100K", "above the memory limit"},
      {"/api/explain?" + cornell() + "&x=1&y=1&max-memory=100K", "above the memory limit"},
      {"/api/explain?" + cornell() + "&size=10,10&x=10&y=0", "x, y: pixel (10, 0) lies outside"},
      {"/api/explain?" + cornell() + "&x=1", "x, y: the pixel to explain is missing"},
      {"/api/explain?" + cornell() + "&x=-1&y=0", "x: '-1' is not a pixel coordinate"},
  };
  for (const auto& [target, message] : cases) {
    const auto r = get(target);
    ASSERT_TRUE(r) << target;
    EXPECT_EQ(r->status, 400) << target;
    EXPECT_NE(r->body.find(message), std::string::npos) << target << " -> " << r->body;
  }
}

// serve --max-memory limits every render; a request may lower the limit,
// not raise it.
TEST(ServeMemory, TheServersLimitHoldsForEveryRequest) {
  serve::ServeOptions options;
  options.scenes = {scenePath("cornell-box")};
  options.port = 0;
  options.memory = MemoryBudget::parse("100K");
  serve::ExplorerServer server(options);
  const int port = server.bind();
  std::thread thread([&] { server.run(); });
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(120, 0);
  const std::string scene = "scene=" + httplib::detail::encode_query_param(scenePath("cornell-box"));
  for (const std::string& extra : {std::string(""), std::string("&max-memory=8G")}) {
    const auto r = client.Get(("/api/image?" + scene + "&size=16x12" + extra).c_str());
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << extra;
    EXPECT_NE(r->body.find("above the memory limit of 100.0 KiB"), std::string::npos) << r->body;
  }
  server.stop();
  thread.join();
}

// One size syntax everywhere: 320x240 as `sweep --vary` writes it; the
// first form, 320,240, reads the same.
TEST_F(ServeTest, SizesReadWidthXHeight) {
  for (const char* size : {"40x30", "40,30"}) {
    const auto r = get("/api/frame?" + cornell() + "&size=" + size);
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200) << size << ": " << r->body;
    EXPECT_EQ(json::parse(r->body)["size"], json::array({40, 30})) << size;
  }
  const auto bad = get("/api/frame?" + cornell() + "&size=40x");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_NE(bad->body.find("size: '40x': needs 2 values joined by 'x' (e.g. 320x240)"), std::string::npos)
      << bad->body;
}

TEST_F(ServeTest, UnknownParameterGets400) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"/api/image?" + cornell() + "&colour=red", "unknown parameter 'colour'"},
      {"/api/image?" + cornell() + "&--spp=4", "unknown parameter '--spp'"},
      {"/api/image?" + cornell() + "&x=3", "unknown parameter 'x'"},  // only explain takes a pixel
      {"/api/image?" + cornell() + "&threads=2", "threads: set by the server"},
      {"/api/image?" + cornell() + "&debug-pixel=1,1", "debug-pixel: set by the server"},
      {"/api/options?verbose=1", "unknown parameter 'verbose'"},
      {"/api/scene?" + cornell() + "&spp=4", "unknown parameter 'spp'"},
      // One value with commas of its own reaches --lights whole.
      {"/api/image?" + cornell() + "&lights=0,3", "lights: light 3 does not exist: the scene has 1 light"},
      {"/api/image?" + cornell() + "&lights=on", "lights: 'on' is not all, none or"},
      {"/api/image?" + cornell() + "&camera=1",
       "camera: camera 1 does not exist: the scene has 1 camera node"},
  };
  for (const auto& [target, message] : cases) {
    const auto r = get(target);
    ASSERT_TRUE(r) << target;
    EXPECT_EQ(r->status, 400) << target;
    EXPECT_NE(r->body.find(message), std::string::npos) << target << " -> " << r->body;
  }
}

// The page's lights and camera controls are built from /api/scene.
TEST_F(ServeTest, SceneInfoListsLightsAndCameras) {
  const auto r = get("/api/scene?" + cornell() + "&size=40,30");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const json j = json::parse(r->body);
  ASSERT_EQ(j["lightList"].size(), 1u);
  EXPECT_EQ(j["lightList"][0]["index"], 0);
  EXPECT_EQ(j["lightList"][0]["name"], "CeilingLight");
  EXPECT_EQ(j["lightList"][0]["type"], "point");
  ASSERT_EQ(j["cameras"].size(), 1u);
  EXPECT_EQ(j["cameras"][0]["index"], 0);
  // The first camera node is the default camera.
  for (const char* key : {"origin", "eye", "target", "up", "yfovDegrees"})
    EXPECT_EQ(j["cameras"][0][key], j["camera"][key]) << key;
}

TEST_F(ServeTest, OnlyNamedScenesAndFilesUnderTheRootCanBeOpened) {
  const auto listed = get("/api/scenes");
  ASSERT_TRUE(listed);
  EXPECT_EQ(json::parse(listed->body)["scenes"],
            json::array({scenePath("cornell-box"), "sub/three-triangles.gltf"}));
  EXPECT_EQ(get("/api/image?scene=sub/three-triangles.gltf&size=16,12")->status, 200);
  EXPECT_EQ(get("/api/image?scene=sub%2Fthree-triangles.gltf&size=16,12")->status, 200);

  const std::string secret = (base_ / "secret.gltf").string();
  const std::vector<std::string> refused = {
      "../secret.gltf",                                    // climbing
      "%2e%2e/secret.gltf",                                // climbing, encoded
      "%2E%2E%2Fsecret.gltf",                              // and the slash too
      "sub/../../secret.gltf",                             // climbing from a subdirectory
      "sub%2F%2e%2e%2F%2e%2e%2Fsecret.gltf",               // likewise, encoded
      "sub/%2e%2e/%2e%2e/secret.gltf",                     //
      httplib::detail::encode_query_param(secret),         // absolute path
      httplib::detail::encode_query_param("/etc/passwd"),  //
      "escape.gltf",                                       // a link out of the root
      "%252e%252e%252fsecret.gltf",                        // double-encoded: a name, not a path
      "sub",                                               // a directory
      "missing.gltf",
  };
  for (const std::string& name : refused) {
    const auto r = get("/api/image?scene=" + name + "&size=16,12");
    ASSERT_TRUE(r) << name;
    EXPECT_TRUE(r->status == 403 || r->status == 404) << name << " -> " << r->status << " " << r->body;
  }
  // The URL path itself opens nothing but the page and the API.
  for (const char* path :
       {"/../secret.gltf", "/%2e%2e/%2e%2e/etc/passwd", "/api/../../etc/passwd", "/etc/passwd"})
    EXPECT_EQ(get(path)->status, 404) << path;
}

TEST_F(ServeTest, RequestsForAnotherHostNameAreRefused) {
  // A page elsewhere whose DNS name is rebound to 127.0.0.1 is refused.
  EXPECT_EQ(get("/api/scenes", "attacker.example:80")->status, 403);
  EXPECT_EQ(get("/api/scenes", "localhost:" + std::to_string(port_))->status, 200);
}

// A request superseded while it renders stops rendering (at its next
// tile) and answers 409: the first render here would take minutes on two
// cores (2048x2048 at 64 spp, ray cast), so a 409 after the newer request
// arrived can only come from the cancelled render; without cancellation it
// would run to the end and answer 200.
TEST_F(ServeTest, RequestSupersededWhileRenderingStops) {
  const std::string slow =
      "/api/image?" + cornell() + "&renderer=raytrace&size=2048x2048&spp=64&client=page9&seq=1";
  std::optional<httplib::Result> first;
  std::thread thread([&] { first = get(slow); });
  // Long enough for the first request to be rendering (its scene loads in
  // milliseconds); the newer one then waits for the render lock.
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const auto second = get("/api/image?" + cornell() + "&size=16x12&client=page9&seq=2");
  thread.join();
  ASSERT_TRUE(first && *first);
  EXPECT_EQ((*first)->status, 409) << (*first)->body;
  EXPECT_EQ((*first)->body, "superseded by a newer request while rendering\n");
  ASSERT_TRUE(second);
  EXPECT_EQ(second->status, 200) << second->body;
}

TEST_F(ServeTest, OlderRequestOfTheSameClientIsSuperseded) {
  const std::string target = "/api/image?" + cornell() + "&size=16,12&client=page1&seq=";
  EXPECT_EQ(get(target + "5")->status, 200);
  const auto older = get(target + "3");
  EXPECT_EQ(older->status, 409);
  EXPECT_NE(older->body.find("superseded by request 5"), std::string::npos);
  EXPECT_EQ(get(target + "6")->status, 200);
  EXPECT_EQ(get("/api/image?" + cornell() + "&size=16,12&client=page2&seq=1")->status, 200);
}

// The command line the page shows renders the same image: the settings
// round-trip through `rastray render`.
TEST_F(ServeTest, SettingsRoundTripThroughTheCommandLine) {
  const std::vector<std::string> settings = {
      "&renderer=raster&size=64,48&spp=4&shadow-map-size=512&depth-format=unorm24&transparency=peel:2",
      "&renderer=hybrid&size=48,40&shadows=map&shadow-bias=0.001,2&cull=back&texture-filter=nearest",
      "&renderer=hybrid&size=48,40&shadows=none&max-depth=0&wireframe=on&halo=on",
      "&renderer=raytrace&size=50,30&spp=2&max-depth=0&origin=world&eye=1.5,0.25,3&target=0,0,0&up=0,1,0",
      "&renderer=raytrace&size=40,30&transparency-cutoff=0&ray-offset=float-ulps&no-packets=on&yfov=60",
      "&renderer=hybrid&size=48,40&shadows=rays&no-shadow-packets=on",
      "&renderer=hybrid&size=48,40&lights=none&camera=0",
      "&renderer=raster&size=40,30&lights=0&camera=0&eye=0.3,0.1,3&target=0,0,0&up=0,1,0",
  };
  int index = 0;
  for (const std::string& s : settings) {
    const auto frame = get("/api/frame?" + cornell() + s);
    ASSERT_TRUE(frame);
    ASSERT_EQ(frame->status, 200) << s << ": " << frame->body;
    const std::string command = json::parse(frame->body)["command"];
    std::vector<std::string> words = shellWords(command);
    ASSERT_GE(words.size(), 5u) << command;
    ASSERT_EQ(words[0], "rastray");
    ASSERT_EQ(words.back(), "render.png") << command;
    const fs::path out = base_ / ("roundtrip-" + std::to_string(index++) + ".png");
    words.back() = out.string();
    const auto run = test::runRastray(std::vector<std::string>(words.begin() + 1, words.end()));
    ASSERT_EQ(run.status, 0) << command << "\n" << run.err;
    const auto image = get("/api/image?" + cornell() + s);
    EXPECT_EQ(image->body, slurp(out)) << command;
  }
}

TEST(ServeApi, ShellQuotingKeepsEveryWord) {
  EXPECT_EQ(serve::shellQuote("scenes/cornell-box.gltf"), "scenes/cornell-box.gltf");
  EXPECT_EQ(serve::shellQuote("my scene.gltf"), "'my scene.gltf'");
  EXPECT_EQ(serve::shellQuote("it's"), "'it'\\''s'");
  EXPECT_EQ(serve::shellQuote(""), "''");
  EXPECT_EQ(shellWords("rastray 'it'\\''s' 'a b' c"),
            (std::vector<std::string>{"rastray", "it's", "a b", "c"}));
}

TEST(ServeApi, Base64MatchesRfc4648) {
  EXPECT_EQ(serve::base64(""), "");
  EXPECT_EQ(serve::base64("f"), "Zg==");
  EXPECT_EQ(serve::base64("fo"), "Zm8=");
  EXPECT_EQ(serve::base64("foo"), "Zm9v");
  EXPECT_EQ(serve::base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(serve::base64(std::string("\xff\x00\x10", 3)), "/wAQ");
}

// /api/options says, for each renderer (or all) and each setting of what
// the conditions read, which options apply and whether --shadows' value is
// taken: the explorer's greying out reads it and keeps no rules of its own.
TEST(ServeApi, ApplicabilityFollowsTheRendersOwnRules) {
  const json table = json::parse(serve::optionTableJson().dump());
  const auto entry = [&](const std::string& renderer, const std::string& shadows, bool wireframe) {
    for (const json& a : table.at("applicability"))
      if (a.at("renderer") == renderer && a.at("shadows") == shadows && a.at("wireframe") == wireframe)
        return a;
    ADD_FAILURE() << renderer << " " << shadows << " " << wireframe << ": no entry";
    return json();
  };
  const auto applies = [](const json& a, const std::string& name) {
    for (const json& n : a.at("applies"))
      if (n == name) return true;
    return false;
  };
  // 4 targets x (default, map, rays, none) x wireframe off/on.
  EXPECT_EQ(table.at("applicability").size(), 32u);
  EXPECT_TRUE(applies(entry("raster", "", false), "shadow-map-size"));
  EXPECT_FALSE(applies(entry("raster", "none", false), "shadow-map-size"));
  EXPECT_FALSE(applies(entry("raytrace", "", false), "shadow-map-size"));
  EXPECT_TRUE(applies(entry("raytrace", "", false), "terminator"));
  EXPECT_TRUE(applies(entry("hybrid", "map", false), "shadow-map-size"));
  EXPECT_FALSE(applies(entry("hybrid", "", false), "shadow-map-size"));
  // With every renderer, the rasterizer's map applies unless shadows are off.
  EXPECT_TRUE(applies(entry("all", "rays", false), "shadow-map-size"));
  EXPECT_FALSE(applies(entry("all", "none", false), "shadow-map-size"));
  // --halo needs --wireframe; the ray caster draws none.
  EXPECT_FALSE(applies(entry("raster", "", false), "halo"));
  EXPECT_TRUE(applies(entry("raster", "", true), "halo"));
  EXPECT_FALSE(applies(entry("raytrace", "", true), "halo"));
  // A refused value carries the command line's message; what applies is
  // then what applies without it (the page leaves it out).
  const json refused = entry("raytrace", "map", false);
  EXPECT_FALSE(refused.at("valid").get<bool>());
  EXPECT_NE(refused.at("error").get<std::string>().find("'map' applies to raster and hybrid"),
            std::string::npos)
      << refused.at("error");
  EXPECT_EQ(refused.at("applies"), entry("raytrace", "", false).at("applies"));
  EXPECT_FALSE(entry("raster", "rays", false).at("valid").get<bool>());
  for (const char* target : {"raster", "raytrace", "hybrid", "all"})
    EXPECT_TRUE(entry(target, "none", false).at("valid").get<bool>()) << target;
  EXPECT_TRUE(entry("all", "rays", false).at("valid").get<bool>());
}

}  // namespace
}  // namespace rastray

#endif  // RASTRAY_HAVE_RENDERERS
