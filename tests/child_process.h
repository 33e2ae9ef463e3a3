// Running a program as a child process in the tests that drive the `lightcuts` binary
// (src/app/cli_test.cpp, src/app/distributed_test.cpp): started in a given directory with
// stdin from /dev/null and stdout/stderr captured to DIR/.stdout and DIR/.stderr, waited for
// with a timeout, signalled, and killed at destruction if still running.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <set>
#include <string>
#include <vector>

namespace lc::testing {

class ChildProcess {
 public:
  using Clock = std::chrono::steady_clock;

  // Starts argv[0] (a path) with argv as its arguments, in `dir`.
  ChildProcess(std::vector<std::string> argv, const std::string& dir);
  // Kills (SIGKILL) and reaps the process if it was not reaped yet.
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }

  // Waits up to `seconds` for the process to end; false on timeout (the process is then killed).
  bool wait(double seconds);
  // Polls stderr until it contains `text`; false when the process ends first or on timeout.
  bool waitForStderr(const std::string& text, double seconds);
  // Sends `sig` to the process.
  void signal(int sig);

  // The exit status, -1 when the process has not exited normally (killed by a signal, not
  // waited for, timed out).
  int status() const { return status_; }
  // The signal that ended the process, 0 when none did.
  int termSignal() const { return signal_; }
  // As a shell reports it: the exit status, 128 + the signal that ended the process, or -1.
  int shellStatus() const { return signal_ ? 128 + signal_ : status_; }

  std::string stdoutText() const;
  std::string stderrText() const;

 private:
  void reaped(int waitStatus);

  std::string outPath_, errPath_;
  pid_t pid_ = -1;
  bool reaped_ = false;
  int status_ = -1, signal_ = 0;
};

// The command line that runs `lightcuts ARGS` (the binary of test_util.h's binary()), after
// `launcher` when one is given (e.g. {"mpirun", "-np", "2"}).
std::vector<std::string> lightcutsCommand(const std::vector<std::string>& args,
                                          const std::vector<std::string>& launcher = {});

// The names of the files in `dir`, without the captured .stdout and .stderr.
std::set<std::string> filesIn(const std::string& dir);

}  // namespace lc::testing
