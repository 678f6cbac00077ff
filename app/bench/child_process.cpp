#include "app/bench/child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "common/interrupt.h"

namespace rastray::crossover {

namespace {

std::string readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::string selfExecutable() {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : p.string();
}

uint64_t availableMemoryBytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  uint64_t value = 0;
  std::string unit;
  while (in >> key >> value) {
    std::getline(in, unit);
    if (key == "MemAvailable:") return value * 1024;  // the file says kB and means KiB
  }
  return 0;
}

ChildResult runChild(const std::string& program, const std::vector<std::string>& args,
                     const std::string& scratchDir, const ChildLimits& limits) {
  ChildResult r;
  const std::string outPath = scratchDir + "/child.out", errPath = scratchDir + "/child.err";
  // Everything the child needs is prepared before fork: between fork and
  // exec only async-signal-safe calls are allowed.
  std::vector<std::string> argvStrings;
  argvStrings.push_back(program);
  argvStrings.insert(argvStrings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argvStrings) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int outFd = ::open(outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int errFd = ::open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int nullFd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (outFd < 0 || errFd < 0 || nullFd < 0) {
    for (int fd : {outFd, errFd, nullFd})
      if (fd >= 0) ::close(fd);
    r.err = "cannot create the child's output files in " + scratchDir;
    return r;
  }
  rlimit as{};
  as.rlim_cur = as.rlim_max = limits.addressSpaceBytes ? rlim_t(limits.addressSpaceBytes) : RLIM_INFINITY;

  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(nullFd, 0);
    ::dup2(outFd, 1);
    ::dup2(errFd, 2);
    if (limits.addressSpaceBytes) ::setrlimit(RLIMIT_AS, &as);
    if (!limits.workingDirectory.empty() && ::chdir(limits.workingDirectory.c_str()) != 0) {
      static const char noDir[] = "cannot enter the working directory\n";
      (void)!::write(2, noDir, sizeof noDir - 1);
      _exit(127);
    }
    ::execv(argv[0], argv.data());
    static const char message[] = "cannot execute the program\n";
    (void)!::write(2, message, sizeof message - 1);
    _exit(127);
  }
  ::close(outFd);
  ::close(errFd);
  ::close(nullFd);
  if (pid < 0) {
    r.err = std::string("fork failed: ") + std::strerror(errno);
    return r;
  }
  r.started = true;

  // Poll with wait4 so the child's own rusage comes back with its status; a
  // 2 ms poll adds at most that to the wall time (the study's times come
  // from the child's own clock, not this one).
  // A stop request (common/interrupt.h) is passed on as SIGTERM: a child
  // in the terminal's process group has had the Ctrl-C itself, one started
  // by a parent that alone was sent SIGTERM has not. It gets 5 s to stop
  // (rastray stops within a tile), then SIGKILL.
  int status = 0;
  rusage usage{};
  double stopSentAt = -1;
  for (;;) {
    const pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) break;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (limits.timeoutSeconds > 0 && elapsed > limits.timeoutSeconds && !r.timedOut) {
      r.timedOut = true;
      ::kill(pid, SIGKILL);
    }
    if (interruptRequested() && stopSentAt < 0) {
      stopSentAt = elapsed;
      ::kill(pid, SIGTERM);
    }
    if (stopSentAt >= 0 && elapsed > stopSentAt + 5.0) ::kill(pid, SIGKILL);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  // The child is gone: the caller's stop comes before anything it said.
  if (stopSentAt >= 0) throwIfInterrupted();
  r.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.peakRssBytes = uint64_t(usage.ru_maxrss) * 1024;  // Linux: KiB
  if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  r.out = readWhole(outPath);
  r.err = readWhole(errPath);
  // exec failed (as opposed to the program, or its dynamic loader, exiting 127).
  if (r.exitCode == 127 && r.err.rfind("cannot execute the program", 0) == 0) r.started = false;
  return r;
}

}  // namespace rastray::crossover
