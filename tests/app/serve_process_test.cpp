// `rastray serve` as users run it: the real binary as a child process, its
// page in headless Chromium (loads, first image, a clicked pixel explained),
// and a clean stop on SIGINT and SIGTERM.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "run_command.h"
#include "tests/test_files.h"
#include "tests/test_labels.h"

namespace rastray {
namespace {

namespace fs = std::filesystem;

std::string scenePath(const char* name) { return std::string(RASTRAY_SCENES) + "/" + name + ".gltf"; }

using test::slurp;

fs::path freshDir(const std::string& name) {
  const fs::path dir = test::scratchDir() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// `rastray serve ARGS --port 0` in a child process with its own TMPDIR;
// the port is read from the line it prints once listening.
class ServeProcess {
 public:
  ServeProcess(std::vector<std::string> args, const fs::path& dir) : errPath_(dir / "serve.err") {
    fs::create_directories(dir / "tmp");
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe");
    pid_ = fork();
    if (pid_ == 0) {
      dup2(out[1], 1);
      const int err = open(errPath_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(err, 2);
      close(out[0]);
      setenv("TMPDIR", (dir / "tmp").c_str(), 1);
      args.insert(args.begin(), {RASTRAY_BINARY, "serve"});
      args.insert(args.end(), {"--port", "0"});
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(RASTRAY_BINARY, argv.data());
      _exit(127);
    }
    close(out[1]);
    port_ = readPort(out[0]);
    close(out[0]);
  }
  ~ServeProcess() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }

  int port() const { return port_; }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_) + "/"; }
  std::string err() const { return slurp(errPath_); }

  // Sends `signal` and waits up to 60 s; the exit status, or -1 when the
  // process did not exit normally in time.
  int stop(int signal) {
    kill(pid_, signal);
    int status = 0;
    for (int i = 0; i < 600; ++i) {
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return -1;
  }

 private:
  // "rastray serve: http://127.0.0.1:PORT/ (Ctrl-C stops)", within 60 s.
  static int readPort(int fd) {
    std::string line;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (line.find('\n') == std::string::npos && std::chrono::steady_clock::now() < deadline) {
      pollfd p{fd, POLLIN, 0};
      if (poll(&p, 1, 100) <= 0) continue;
      char buf[256];
      const ssize_t n = read(fd, buf, sizeof buf);
      if (n <= 0) break;
      line.append(buf, size_t(n));
    }
    std::smatch m;
    if (!std::regex_search(line, m, std::regex("http://127\\.0\\.0\\.1:([0-9]+)/"))) return -1;
    return std::stoi(m[1]);
  }

  fs::path errPath_;
  pid_t pid_ = -1;
  int port_ = -1;
  bool exited_ = false;
};

// The page in a real browser: it loads, shows the first image, a drag
// orbits the camera (the refined image's command line has --eye), a click
// on a pixel fills the explain panel and draws the ray tree. The mouse
// events go through the page's own handlers (the ?selftest hook), which
// reports in #selftest-result; --dump-dom prints it.
RASTRAY_TEST_LABELS_OF(ServeBrowser, PageShowsTheImageAndExplainsAClickedPixel, "browser");
TEST(ServeBrowser, PageShowsTheImageAndExplainsAClickedPixel) {
  const char* chromium = "/usr/bin/chromium";
  ASSERT_TRUE(fs::exists(chromium))
      << "Chromium is not installed: run scripts/setup.sh (it installs the Debian "
         "package chromium), the browser test must not be skipped";
  const fs::path dir = freshDir("serve-browser");
  ServeProcess server({scenePath("cornell-box")}, dir);
  ASSERT_GT(server.port(), 0) << server.err();
  const std::string page =
      server.url() + "?renderer=raytrace&size=160,120&spp=4&selftest=drag:30,-10;click:70,40";
  const fs::path dom = dir / "dom.html";
  const std::string cmd = std::string("timeout 300 ") + chromium +
                          " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
                          "--disable-background-networking --disable-component-update --disable-sync "
                          "--user-data-dir=" +
                          (dir / "profile").string() +
                          " --window-size=1400,900 --virtual-time-budget=120000 --dump-dom '" + page +
                          "' > " + dom.string() + " 2>" + (dir / "chromium.err").string();
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(dir / "chromium.err");
  const std::string html = slurp(dom);
  std::smatch result;
  ASSERT_TRUE(std::regex_search(html, result, std::regex("<div id=\"selftest-result\"[^>]*>([^<]*)</div>")))
      << "no self-test result in the page:\n"
      << html.substr(0, 4000);
  EXPECT_NE(result[0].str().find("data-status=\"ok\""), std::string::npos) << result[0];
  EXPECT_NE(result[1].str().find("drag to eye "), std::string::npos) << result[1];
  EXPECT_NE(result[1].str().find("pixel (70, 40), 4 samples"), std::string::npos) << result[1];
  // The first image arrived as a PNG, the explain panel is filled, and the
  // ray tree is drawn over the image (a shadow ray per sample at least).
  EXPECT_NE(html.find("id=\"image-a\" alt=\"render\" src=\"data:image/png;base64,"), std::string::npos);
  EXPECT_NE(html.find("class=\"explain-done\""), std::string::npos);
  EXPECT_NE(html.find("hits per sample"), std::string::npos);
  EXPECT_NE(html.find("class=\"ray ray-shadow"), std::string::npos);
  EXPECT_NE(html.find("rastray render " + scenePath("cornell-box") + " --renderer raytrace --eye "),
            std::string::npos);
  // What applies to the ray caster, as /api/options' applicability says
  // (the page keeps no copy of the rules): the map size is greyed out and
  // disabled, the terminator is not, and --shadows map cannot be chosen.
  EXPECT_TRUE(std::regex_search(
      html, std::regex("<label class=\"na\"[^>]*>map size <select data-option=\"shadow-map-size\" disabled")))
      << html.substr(html.find("map size") - 200, 400);
  EXPECT_TRUE(
      std::regex_search(html, std::regex("<label[^>]*>terminator <select data-option=\"terminator\">")));
  EXPECT_FALSE(std::regex_search(html, std::regex("<label class=\"na\"[^>]*>terminator")));
  EXPECT_TRUE(std::regex_search(html, std::regex("<option disabled=\"\">map</option><option>rays</option>")));
  EXPECT_EQ(server.stop(SIGTERM), 128 + SIGTERM) << server.err();
  fs::remove_all(dir);
}

// Ctrl-C or SIGTERM stop the server: the exit status of every command a
// signal stopped (128 + signal, common/interrupt.h), and its scratch
// directory (in TMPDIR) is gone, so it shut down through its destructors.
TEST(ServeProcess, StopsCleanlyOnSigintAndSigterm) {
  for (const int signal : {SIGINT, SIGTERM}) {
    const fs::path dir = freshDir("serve-signal");
    ServeProcess server({scenePath("three-triangles")}, dir);
    ASSERT_GT(server.port(), 0) << server.err();
    EXPECT_FALSE(fs::is_empty(dir / "tmp"));  // the scratch directory exists while it runs
    EXPECT_EQ(server.stop(signal), 128 + signal) << server.err();
    EXPECT_NE(server.err().find(signal == SIGINT ? "interrupted by SIGINT: the server stopped"
                                                 : "interrupted by SIGTERM: the server stopped"),
              std::string::npos)
        << server.err();
    EXPECT_TRUE(fs::is_empty(dir / "tmp"));
    fs::remove_all(dir);
  }
}

// serve honours --max-memory as the other commands do (it was refused).
TEST(ServeProcess, AcceptsMaxMemory) {
  const fs::path dir = freshDir("serve-max-memory");
  ServeProcess server({scenePath("three-triangles"), "--max-memory", "1G"}, dir);
  ASSERT_GT(server.port(), 0) << server.err();
  EXPECT_EQ(server.stop(SIGTERM), 128 + SIGTERM) << server.err();
  fs::remove_all(dir);
}

TEST(ServeProcess, BadCommandLineExitsWithStatus2) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"serve"}, "name at least one scene, or a --root directory"},
      {{"serve", "no-such-scene.gltf"}, "no-such-scene.gltf: no such file"},
      {{"serve", "--root", "no-such-directory"}, "--root: 'no-such-directory' is not a directory"},
      {{"serve", scenePath("three-triangles"), "--port", "70000"}, "--port"},
      {{"serve", scenePath("three-triangles"), "--host", "192.0.2.1", "--port", "1"}, "cannot listen on"},
      {{"serve", scenePath("three-triangles"), "--max-memory", "1Q"}, "command line: --max-memory: "},
  };
  for (const auto& [args, message] : cases) {
    const auto r = test::runRastray(args);
    EXPECT_EQ(r.status, 2) << args.back();
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace rastray
