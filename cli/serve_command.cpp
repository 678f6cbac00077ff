// `rastray serve SCENE... [--port 8080] [--host 127.0.0.1] [--root DIR]`:
// the browser explorer (app/serve/serve_server.h).
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <thread>

#include "app/serve/serve_server.h"
#include "cli/commands.h"
#include "common/error.h"
#include "common/interrupt.h"

namespace rastray {

namespace {

struct ServeCommandOptions {
  serve::ServeOptions server;
  std::string maxMemory;  // empty: MemoryBudget::machineDefault()
};

// SIGINT and SIGTERM stop the server cleanly, through the handlers every
// long-running command installs (common/interrupt.h: they only record the
// signal). This watcher polls the record and stops the server; a render
// under way stops at its next tile (the renderers poll the same record),
// and a second Ctrl-C ends the process at once.
class InterruptWatcher {
 public:
  explicit InterruptWatcher(serve::ExplorerServer& server) {
    installInterruptHandlers();
    thread_ = std::thread([this, &server] {
      while (!done_ && !interruptRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      // Server::stop() does nothing before the server's loop has started
      // (a signal just after the address was printed): repeat it until
      // run() has returned.
      while (!done_) {
        server.stop();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    });
  }
  ~InterruptWatcher() {
    done_ = true;
    thread_.join();
  }

 private:
  std::atomic<bool> done_{false};
  std::thread thread_;
};

int runServe(ServeCommandOptions& opt) {
  if (opt.server.scenes.empty() && opt.server.root.empty())
    throw InputError("command line", "SCENE", "name at least one scene, or a --root directory");
  if (!opt.maxMemory.empty()) opt.server.memory = MemoryBudget::parse(opt.maxMemory);
  serve::ExplorerServer server(opt.server);
  bool ok = false;
  {
    // Before the address is printed: from then on a signal stops the server.
    InterruptWatcher watcher(server);
    const int port = server.bind();
    const bool local =
        opt.server.host == "127.0.0.1" || opt.server.host == "localhost" || opt.server.host == "::1";
    if (!local)
      std::fprintf(
          stderr, "rastray serve: listening on %s: anyone who can reach this address can render the scenes\n",
          opt.server.host.c_str());
    const std::string host =
        opt.server.host.find(':') != std::string::npos ? "[" + opt.server.host + "]" : opt.server.host;
    std::printf("rastray serve: http://%s:%d/ (Ctrl-C stops)\n", host.c_str(), port);
    std::fflush(stdout);
    ok = server.run();
  }
  // Stopped by a signal: the exit status every command gives (130, 143).
  if (interruptRequested())
    throw Interrupted(interruptSignal(), "the server stopped, nothing left unfinished");
  return ok ? 0 : 2;
}

}  // namespace

CommandRunner addServeCommand(CLI::App& app) {
  auto opt = std::make_shared<ServeCommandOptions>();
  CLI::App* cmd =
      app.add_subcommand("serve", "Explore scenes in the browser: renders, maps, pixel explanations");
  cmd->add_option("scene", opt->server.scenes, "glTF 2.0 files the page may open");
  cmd->add_option("--port", opt->server.port, "TCP port (0: any free port, printed)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  cmd->add_option("--host", opt->server.host,
                  "Address to listen on; anything but 127.0.0.1 lets other machines render the scenes")
      ->capture_default_str();
  cmd->add_option("--root", opt->server.root,
                  "Directory whose glTF files (and nothing outside it) may be opened");
  cmd->add_option(
      "--max-memory", opt->maxMemory,
      "Refuse (HTTP 400) a scene load or render whose estimated peak memory exceeds this: bytes "
      "or K, M, G, T (default: 80% of physical memory); a request's max-memory may only lower it");
  return [opt, cmd]() -> int { return cmd->parsed() ? runServe(*opt) : -1; };
}

}  // namespace rastray
