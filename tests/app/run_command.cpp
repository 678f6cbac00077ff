#include "run_command.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include "tests/test_files.h"

namespace rastray::test {

CommandResult runRastrayAndSignal(const std::vector<std::string>& args, int signal,
                                  const std::function<bool(pid_t)>& ready, bool* signalled) {
  static std::atomic<int> counter{0};
  const std::string base = "run_" + std::to_string(getpid()) + "_" + std::to_string(counter++);
  const std::string outPath = base + ".out", errPath = base + ".err";
  const pid_t pid = fork();
  if (pid == 0) {
    const int out = open(outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(out, 1);
    dup2(err, 2);
    std::vector<char*> argv;
    std::string binary = RASTRAY_BINARY;
    argv.push_back(binary.data());
    std::vector<std::string> copies(args);
    for (std::string& a : copies) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(binary.c_str(), argv.data());
    _exit(127);
  }
  int wstatus = 0;
  bool sent = false;
  if (ready) {
    while (waitpid(pid, &wstatus, WNOHANG) == 0) {
      if (ready(pid)) {
        kill(pid, signal);
        sent = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    if (sent) waitpid(pid, &wstatus, 0);
  } else {
    waitpid(pid, &wstatus, 0);
  }
  if (signalled) *signalled = sent;
  CommandResult r;
  r.status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
  r.out = slurp(outPath);
  r.err = slurp(errPath);
  std::remove(outPath.c_str());
  std::remove(errPath.c_str());
  return r;
}

CommandResult runRastray(const std::vector<std::string>& args) {
  return runRastrayAndSignal(args, 0, nullptr);
}

bool catchesStopSignals(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("SigCgt:", 0) != 0) continue;
    const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
    const unsigned long long wanted = (1ull << (SIGINT - 1)) | (1ull << (SIGTERM - 1));
    return (mask & wanted) == wanted;
  }
  return false;
}

}  // namespace rastray::test
