#pragma once
// A test server in a child process on loopback (the Python HTTP server, the node S3 server).
// Header only, so that benchmark programs (which do not link the test support library) can use
// it too. The child binds port 0 and reports its port as its first output line "PORT n"; it exits
// when its standard input closes, so it dies with the test process even when that is killed.

#include <csignal>
#include <stdexcept>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

namespace resoct::test {

class LoopbackServerProcess {
 public:
  /// Runs argv[0] (searched on PATH) with the other arguments. Throws std::runtime_error naming
  /// `what` and the child's first line when it does not report a port.
  LoopbackServerProcess(const std::vector<std::string>& argv, const std::string& what) {
    int to_child[2], from_child[2];
    if (::pipe2(to_child, O_CLOEXEC) != 0 || ::pipe2(from_child, O_CLOEXEC) != 0) {
      throw std::runtime_error("pipe failed");
    }
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      ::dup2(to_child[0], 0);
      ::dup2(from_child[1], 1);
      ::execvp(args[0], args.data());
      ::_exit(127);
    }
    ::close(to_child[0]);
    ::close(from_child[1]);
    stdin_fd_ = to_child[1];
    std::string line;
    char c = 0;
    while (::read(from_child[0], &c, 1) == 1 && c != '\n') line.push_back(c);
    ::close(from_child[0]);
    if (line.rfind("PORT ", 0) != 0) {
      stop();
      throw std::runtime_error(what + " did not start: '" + line + "'");
    }
    port_ = std::stoi(line.substr(5));
  }
  ~LoopbackServerProcess() { stop(); }
  LoopbackServerProcess(const LoopbackServerProcess&) = delete;
  LoopbackServerProcess& operator=(const LoopbackServerProcess&) = delete;

  int port() const { return port_; }

 private:
  void stop() {
    if (stdin_fd_ >= 0) ::close(stdin_fd_);
    stdin_fd_ = -1;
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
  }

  pid_t pid_ = -1;
  int stdin_fd_ = -1;
  int port_ = 0;
};

}  // namespace resoct::test
