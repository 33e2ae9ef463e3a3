#include "child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <thread>

#include "test_util.h"

namespace lc::testing {

ChildProcess::ChildProcess(std::vector<std::string> argv, const std::string& dir) {
  outPath_ = dir + "/.stdout";
  errPath_ = dir + "/.stderr";
  pid_ = fork();
  if (pid_ == 0) {
    if (chdir(dir.c_str()) != 0) _exit(126);
    int o = open(outPath_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int e = open(errPath_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (o < 0 || e < 0) _exit(126);
    dup2(o, 1);
    dup2(e, 2);
    int null = open("/dev/null", O_RDONLY);
    if (null >= 0) dup2(null, 0);
    std::vector<char*> cargv;
    for (std::string& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    execv(cargv[0], cargv.data());
    _exit(127);
  }
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && !reaped_) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

void ChildProcess::reaped(int st) {
  reaped_ = true;
  if (WIFEXITED(st)) status_ = WEXITSTATUS(st);
  if (WIFSIGNALED(st)) signal_ = WTERMSIG(st);
}

bool ChildProcess::wait(double seconds) {
  auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    int st = 0;
    if (waitpid(pid_, &st, WNOHANG) == pid_) {
      reaped(st);
      return true;
    }
    if (Clock::now() > deadline) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      reaped_ = true;
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

bool ChildProcess::waitForStderr(const std::string& text, double seconds) {
  auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < deadline) {
    if (stderrText().find(text) != std::string::npos) return true;
    int st = 0;
    if (waitpid(pid_, &st, WNOHANG) == pid_) {
      reaped(st);
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

void ChildProcess::signal(int sig) { kill(pid_, sig); }

std::string ChildProcess::stdoutText() const { return slurp(outPath_); }
std::string ChildProcess::stderrText() const { return slurp(errPath_); }

std::vector<std::string> lightcutsCommand(const std::vector<std::string>& args,
                                          const std::vector<std::string>& launcher) {
  std::vector<std::string> argv = launcher;
  argv.push_back(binary());
  argv.insert(argv.end(), args.begin(), args.end());
  return argv;
}

std::set<std::string> filesIn(const std::string& dir) {
  std::set<std::string> s;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    std::string n = e.path().filename().string();
    if (n != ".stdout" && n != ".stderr") s.insert(n);
  }
  return s;
}

}  // namespace lc::testing
