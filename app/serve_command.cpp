// `rastray serve SCENE... [--port 8080] [--host 127.0.0.1] [--root DIR]`:
// the browser explorer (app/serve_server.h).
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <thread>

#include "app/commands.h"
#include "app/serve_server.h"
#include "common/error.h"

namespace rastray {

namespace {

struct ServeCommandOptions {
  serve::ServeOptions server;
};

// SIGINT and SIGTERM stop the server cleanly. They are blocked in every
// thread (the server's and TBB's inherit the mask from this one) and taken
// by one watcher with sigwait(): no signal handler runs at all, so nothing
// has to be async-signal-safe, and the watcher may call Server::stop().
class SignalWatcher {
 public:
  explicit SignalWatcher(serve::ExplorerServer& server) {
    sigemptyset(&signals_);
    sigaddset(&signals_, SIGINT);
    sigaddset(&signals_, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals_, &previous_);
    thread_ = std::thread([this, &server] {
      int signal = 0;
      sigwait(&signals_, &signal);
      if (done_) return;
      std::fprintf(stderr, "rastray serve: %s, stopping\n", signal == SIGINT ? "interrupted" : "terminated");
      // Server::stop() does nothing before the server's loop has started
      // (a signal just after the address was printed): repeat it until
      // run() has returned.
      while (!done_) {
        server.stop();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    });
  }
  // Ends the watcher once the server has stopped: wakes it from sigwait()
  // when no signal came, or ends its stop() loop.
  ~SignalWatcher() {
    done_ = true;
    pthread_kill(thread_.native_handle(), SIGTERM);  // blocked here: only sigwait() takes it
    thread_.join();
    pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
  }

 private:
  sigset_t signals_, previous_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

int runServe(ServeCommandOptions& opt) {
  if (opt.server.scenes.empty() && opt.server.root.empty())
    throw InputError("command line", "SCENE", "name at least one scene, or a --root directory");
  serve::ExplorerServer server(opt.server);
  // Block the signals before the server starts its threads.
  SignalWatcher watcher(server);
  const int port = server.bind();
  const bool local =
      opt.server.host == "127.0.0.1" || opt.server.host == "localhost" || opt.server.host == "::1";
  if (!local)
    std::fprintf(stderr,
                 "rastray serve: listening on %s: anyone who can reach this address can render the scenes\n",
                 opt.server.host.c_str());
  const std::string host =
      opt.server.host.find(':') != std::string::npos ? "[" + opt.server.host + "]" : opt.server.host;
  std::printf("rastray serve: http://%s:%d/ (Ctrl-C stops)\n", host.c_str(), port);
  std::fflush(stdout);
  const bool ok = server.run();
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
  return [opt, cmd]() -> int { return cmd->parsed() ? runServe(*opt) : -1; };
}

}  // namespace rastray
