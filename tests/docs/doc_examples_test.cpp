// Every command example in README.md and docs/*.md runs here against the
// built binary, as written (slow steps shrunk where the doc says how), and
// must exit as documented, leave the files it names and print output of
// the shape its sample shows. The marker convention is in doc_examples.h.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "tests/docs/doc_examples.h"
#include "tests/test_files.h"
#include "tests/test_labels.h"

// Each example runs the built binary as the docs show it: seconds each.
RASTRAY_TEST_LABELS("slow");

namespace rastray::test::docs {
namespace {
namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string out, err;
};

// A scratch directory laid out like a checkout: scenes/, build/rastray, and
// `rastray` on PATH.
fs::path prepareDirectory() {
  const fs::path dir = scratchDir();
  fs::create_directories(dir / "build");
  fs::create_symlink(fs::path(RASTRAY_SOURCE_DIR) / "scenes", dir / "scenes");
  fs::create_directories(dir / "tests");
  fs::create_symlink(fs::path(RASTRAY_SOURCE_DIR) / "tests" / "data", dir / "tests" / "data");
  fs::create_symlink(RASTRAY_BINARY, dir / "build" / "rastray");
  return dir;
}

// Starts `/bin/sh -c line` in `dir` with stdout and stderr to files.
pid_t spawnShell(const std::string& line, const fs::path& dir, const fs::path& out, const fs::path& err) {
  const std::string path = (dir / "build").string() + ":" + (std::getenv("PATH") ? std::getenv("PATH") : "");
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(127);
    const int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(o, 1);
    ::dup2(e, 2);
    ::setenv("PATH", path.c_str(), 1);
    // One process group, so a stop reaches the shell's children too.
    ::setpgid(0, 0);
    ::execl("/bin/sh", "sh", "-c", ("exec " + line).c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

int waitStatus(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// A command line through the shell; `timeout` bounds a hanging example.
Result runShell(const std::string& line, const fs::path& dir, int step) {
  const fs::path out = dir / ("step" + std::to_string(step) + ".out");
  const fs::path err = dir / ("step" + std::to_string(step) + ".err");
  std::ofstream(dir / "command.sh") << line << "\n";
  Result r;
  r.status = waitStatus(spawnShell("timeout 1200 /bin/sh command.sh", dir, out, err));
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// Runs the commands of a Run or Pending block; "" when all went as
// documented, else what did not.
std::string runBlock(const Block& b, const fs::path& dir) {
  std::string out, err;
  int step = 0;
  for (const Command& c : b.commands) {
    const std::string line = c.tested_with.empty() ? c.line : applyOverrides(c.line, c.tested_with);
    const Result r = runShell(line, dir, step++);
    out += r.out;
    err += r.err;
    std::ostringstream where;
    where << b.file << ":" << c.line_number << ": `" << line << "`";
    if (r.status != c.expected_status)
      return where.str() + " exited " + std::to_string(r.status) + ", the doc says " +
             std::to_string(c.expected_status) + "\nstdout:\n" + r.out + "\nstderr:\n" + r.err;
    for (const std::string& f : c.writes)
      if (!fs::exists(dir / f)) return where.str() + " did not write " + f;
  }
  std::string missing;
  if (!matchesSample(b.sample, out, err, &missing))
    return b.file + ":" + std::to_string(b.line_number) +
           ": the output has no line shaped like the sample's\n  " + missing + "\nstdout:\n" + out +
           "\nstderr:\n" + err;
  return "";
}

// A `sh serve` block: the server on a free port (`--port 0`, the address it
// prints replaces 127.0.0.1:8080 in the curl lines), each curl line, then
// SIGTERM, which the server answers with exit status 143.
std::string runServeBlock(const Block& b, const fs::path& dir) {
  const fs::path out = dir / "serve.out", err = dir / "serve.err";
  const pid_t server = spawnShell(b.commands[0].line + " --port 0", dir, out, err);
  static const std::regex address(R"(http://127\.0\.0\.1:(\d+)/)");
  std::smatch m;
  std::string printed;
  int exited = -1;                 // the server's exit status if it stopped by itself
  for (int i = 0; i < 600; ++i) {  // at most 60 s to load the scenes
    printed = slurp(out);
    if (std::regex_search(printed, m, address)) break;
    int status = 0;
    if (::waitpid(server, &status, WNOHANG) == server) {
      exited = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (exited >= 0)
    return "the server exited " + std::to_string(exited) + " before it listened:\n" + printed + slurp(err);
  std::string failure;
  if (m.empty()) failure = "the server printed no address:\n" + printed + slurp(err);
  int step = 0;
  for (size_t i = 1; i < b.commands.size() && failure.empty(); ++i) {
    const Command& c = b.commands[i];
    const std::string line =
        std::regex_replace(c.line, std::regex(R"(127\.0\.0\.1:8080)"), "127.0.0.1:" + m[1].str());
    const Result r = runShell(line, dir, step++);
    if (r.status != c.expected_status)
      failure = b.file + ":" + std::to_string(c.line_number) + ": `" + line + "` exited " +
                std::to_string(r.status) + "\n" + r.out + r.err;
    for (const std::string& f : c.writes)
      if (failure.empty() && !fs::exists(dir / f)) failure = b.file + ": `" + line + "` did not write " + f;
  }
  ::kill(server, SIGTERM);
  const int status = waitStatus(server);
  if (failure.empty() && status != 143)
    failure = "the server exited " + std::to_string(status) + " on SIGTERM, the docs say 143";
  std::string missing;
  if (failure.empty() && !matchesSample(b.sample, slurp(out), slurp(err), &missing))
    failure = "the server's output has no line shaped like\n  " + missing;
  return failure;
}

class DocExample : public ::testing::TestWithParam<Block> {};

TEST_P(DocExample, RunsAsDocumented) {
  const Block& b = GetParam();
  ASSERT_TRUE(b.error.empty()) << b.file << ":" << b.line_number << ": " << b.error;
  switch (b.kind) {
    case BlockKind::NotRun:
      GTEST_SKIP() << b.file << ":" << b.line_number << " is not run: " << b.reason;
    case BlockKind::Ci: {
      // The README's commands are what CI runs, word for word.
      const std::string ci = slurp(fs::path(RASTRAY_SOURCE_DIR) / ".ci" / "run");
      for (const Command& c : b.commands)
        EXPECT_NE(ci.find("\n" + c.line + "\n"), std::string::npos) << "not a line of .ci/run: " << c.line;
      return;
    }
    case BlockKind::Serve: {
      const std::string failure = runServeBlock(b, prepareDirectory());
      if (!b.pending) {
        EXPECT_TRUE(failure.empty()) << failure;
        return;
      }
      if (failure.empty())
        FAIL() << b.file << ":" << b.line_number << " works now: remove its `pending: " << b.reason
               << "` marker";
      GTEST_SKIP() << "pending (" << b.reason << "): " << failure.substr(0, failure.find('\n'));
    }
    case BlockKind::Run: {
      const std::string failure = runBlock(b, prepareDirectory());
      EXPECT_TRUE(failure.empty()) << failure;
      return;
    }
    case BlockKind::Pending: {
      const std::string failure = runBlock(b, prepareDirectory());
      if (failure.empty())
        FAIL() << b.file << ":" << b.line_number << " works now: remove its `pending: " << b.reason
               << "` marker";
      GTEST_SKIP() << "pending (" << b.reason << "): " << failure.substr(0, failure.find('\n'));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Docs, DocExample, ::testing::ValuesIn(loadBlocks(RASTRAY_SOURCE_DIR)),
                         [](const ::testing::TestParamInfo<Block>& p) { return p.param.name(); });

// The convention itself, on a page written for the purpose.
TEST(DocExampleMarkers, ParseEveryMarker) {
  const std::string page =
      "```sh\n"
      "rastray render scenes/a.gltf -o a.png  # writes a.png\n"
      "./build/rastray render nothing.gltf \\\n"
      "    -o b.png  # exits 2\n"
      "```\n"
      "prose\n"
      "```text\n"
      "scene  a.gltf\n"
      "```\n"
      "```sh not-run: needs Slurm\n"
      "sbatch sweep.sh\n"
      "```\n"
      "```sh pending: issue 99\n"
      "rastray bench x --frames 10  # slow, tested with --frames 1 --size 8 6\n"
      "```\n"
      "```sh serve\n"
      "rastray serve scenes/a.gltf\n"
      "curl -fsS http://127.0.0.1:8080/api/scenes\n"
      "```\n"
      "```sh serve pending: issue 98\n"
      "rastray serve scenes/a.gltf\n"
      "```\n"
      "```sh\n"
      "ls\n"
      "```\n"
      "```python\n"
      "print(1)\n"
      "```\n";
  const std::vector<Block> blocks = parseMarkdown(page, "page.md");
  ASSERT_EQ(blocks.size(), 6u);
  EXPECT_EQ(blocks[0].kind, BlockKind::Run);
  ASSERT_EQ(blocks[0].commands.size(), 2u);
  EXPECT_EQ(blocks[0].commands[0].writes, std::vector<std::string>{"a.png"});
  EXPECT_EQ(blocks[0].commands[1].line, "./build/rastray render nothing.gltf -o b.png");
  EXPECT_EQ(blocks[0].commands[1].expected_status, 2);
  EXPECT_EQ(blocks[0].sample, std::vector<std::string>{"scene  a.gltf"});
  EXPECT_EQ(blocks[1].kind, BlockKind::NotRun);
  EXPECT_EQ(blocks[1].reason, "needs Slurm");
  EXPECT_EQ(blocks[2].kind, BlockKind::Pending);
  EXPECT_EQ(blocks[2].commands[0].tested_with, "--frames 1 --size 8 6");
  EXPECT_EQ(blocks[3].kind, BlockKind::Serve);
  EXPECT_TRUE(blocks[3].error.empty()) << blocks[3].error;
  EXPECT_FALSE(blocks[3].pending);
  EXPECT_TRUE(blocks[4].pending);
  EXPECT_EQ(blocks[4].reason, "issue 98");
  EXPECT_NE(blocks[5].error.find("not a rastray command"), std::string::npos);
  EXPECT_EQ(blocks[1].name(), "page_md_L10");
}

TEST(DocExampleMarkers, ATextBlockNeedsAnExampleBefore) {
  const std::vector<Block> blocks = parseMarkdown("```text\nfoo\n```\n", "p.md");
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_FALSE(blocks[0].error.empty());
}

TEST(DocExampleMarkers, OverridesReplaceOrAppendValues) {
  EXPECT_EQ(
      applyOverrides("rastray bench s --size 1920 1080 --frames 10 --peers", "--frames 1 --size 160 120"),
      "rastray bench s --size 160 120 --frames 1 --peers");
  EXPECT_EQ(applyOverrides("rastray stability --report r", "--case zfight"),
            "rastray stability --report r --case zfight");
}

TEST(DocExampleMarkers, SamplesMatchByShapeNotByNumbers) {
  const std::string out =
      "scene   size  spp  agree%\n"
      "cornell-box.gltf  160x120    4  99.9896\n";
  std::string missing;
  EXPECT_TRUE(
      matchesSample({"scene size spp agree%", "...", "cornell-box.gltf 320x240 16 98.5"}, out, "", &missing))
      << missing;
  // A renamed column, a missing row or rows out of order do not match.
  EXPECT_FALSE(matchesSample({"scene size spp agreement"}, out, "", &missing));
  EXPECT_EQ(missing, "scene size spp agreement");
  EXPECT_FALSE(matchesSample({"cornell-box.gltf 1x1 1 1", "scene size spp agree%"}, out, "", &missing));
  // Errors are found on stderr.
  EXPECT_TRUE(matchesSample({"x.gltf: accessor 3: bad"}, "", "x.gltf: accessor 7: bad\n", &missing));
}

// Pages: every relative link and image resolves, the README stays short,
// conventions are linked, not cited by section number, and every page
// under docs/ is reachable from the README.
TEST(DocPages, LinksResolveAndTheReadmeFits) {
  const fs::path root = RASTRAY_SOURCE_DIR;
  std::vector<fs::path> pages = {root / "README.md"};
  for (const auto& e : fs::directory_iterator(root / "docs"))
    if (e.path().extension() == ".md") pages.push_back(e.path());
  static const std::regex link(R"(\]\(([^)\s]+)\))");
  const std::string readme = slurp(root / "README.md");
  EXPECT_LE(std::count(readme.begin(), readme.end(), '\n'), 300) << "README.md is over 300 lines";
  for (const fs::path& page : pages) {
    const std::string text = slurp(page);
    for (auto it = std::sregex_iterator(text.begin(), text.end(), link); it != std::sregex_iterator(); ++it) {
      std::string target = (*it)[1].str();
      if (target.rfind("http", 0) == 0 || target[0] == '#') continue;
      target = target.substr(0, target.find('#'));
      EXPECT_TRUE(fs::exists(page.parent_path() / target))
          << page.filename() << " links to missing " << target;
    }
    if (page.filename() != "CONVENTIONS.md") {
      EXPECT_EQ(text.find("SPEC §"), std::string::npos)
          << page.filename() << " cites SPEC §: link docs/CONVENTIONS.md";
    }
    EXPECT_EQ(text.find("../shared/"), std::string::npos)
        << page.filename() << " points outside the repository";
    static const std::regex history(R"(What changed for issue|Before this issue|\(issue \d+\)|issue \d+'s)");
    // PERFORMANCE.md belongs to the performance work, which rewords its
    // "Before this issue" line; until then it is the one known exception,
    // and the exception fails as soon as it is no longer needed.
    if (page.filename() == "PERFORMANCE.md")
      EXPECT_TRUE(std::regex_search(text, history))
          << "PERFORMANCE.md has no history left: drop its exception";
    else
      EXPECT_FALSE(std::regex_search(text, history)) << page.filename() << " carries history";
    if (page.parent_path().filename() == "docs") {
      EXPECT_NE(readme.find("docs/" + page.filename().string()), std::string::npos)
          << "README.md does not link " << page.filename();
    }
  }
}

}  // namespace
}  // namespace rastray::test::docs
