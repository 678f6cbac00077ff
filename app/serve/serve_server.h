// The HTTP server of `rastray serve` (cpp-httplib): the explorer page and
// its API, one render at a time.
//
//   GET /, /explorer.js, /explorer.css   the page (app/serve/web_assets.h)
//   GET /api/options    the render options a request may set (serve_api.h)
//   GET /api/scenes     the scene names a request may give
//   GET /api/scene      ?scene=S[&size=W,H]: counts, bounds, the file's camera
//   GET /api/frame      ?scene=S&view=V&<render options>: JSON with the image
//                       as a PNG data URL, the work of the render(s) and the
//                       equivalent command line
//   GET /api/image      the same parameters: the PNG alone
//   GET /api/explain    ?scene=S&x=X&y=Y&<render options>: `explain --json`,
//                       its text, the ray tree projected onto the image and
//                       the command line
//
// Errors are text/plain: 400 bad or unknown parameter (the render command's
// own message), 403/404 a scene outside what the server may open, 409 a
// request superseded by a newer one of the same client, 500 a failure.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/memory_budget.h"

namespace rastray::serve {

struct ServeOptions {
  std::vector<std::string> scenes;  // files named on the command line
  std::string root;                 // directory whose glTF files may be opened; empty: none
  std::string host = "127.0.0.1";
  int port = 8080;  // 0: any free port
  // serve --max-memory: the limit of every scene load and render; a
  // request's own max-memory may only lower it. nullopt: the machine
  // default, as for the other commands.
  std::optional<MemoryBudget> memory;
};

class ExplorerServer {
 public:
  // Checks the scenes and the root (InputError); does not bind yet.
  explicit ExplorerServer(const ServeOptions& options);
  ~ExplorerServer();
  ExplorerServer(const ExplorerServer&) = delete;
  ExplorerServer& operator=(const ExplorerServer&) = delete;

  // Binds the socket; returns the port (the one chosen for port 0).
  // Throws InputError (command line, --port) when it cannot.
  int bind();
  // Serves until stop(); returns false when the server failed.
  bool run();
  // Thread-safe; a render under way finishes first.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rastray::serve
