// A landing system in another process (process_system.hpp): the host side
// of the system protocol (system_protocol.hpp). The child's stdin and
// stdout are one end of a socketpair(2) (send(2) with MSG_NOSIGNAL: a
// child that died is an EPIPE, never a SIGPIPE that kills the host); every
// wait is a poll(2) with the remaining timeout. fork(2) then, in the child,
// only async-signal-safe calls before execve(2) (the host has threads).
#include "touchdown/scenario/process_system.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "scenario/fd_wait.hpp"
#include "touchdown/core/child_processes.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/scenario/system_protocol.hpp"

namespace touchdown::scenario {

namespace {

using Clock = std::chrono::steady_clock;
using Deadline = Clock::time_point;
using touchdown::detail::format_fixed;

Deadline after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

/// Non-blocking reads tried before a wait in poll().
constexpr int kSpins = 200;
/// How often a wait looks whether the child has ended [s].
constexpr double kEndedCheckSeconds = 0.1;

/// A payload in place: bytes the caller keeps alive while they are sent.
struct Bytes {
  const void* data = nullptr;
  std::size_t size = 0;
};

/// The system's fault: ScenarioRun makes it the run's "system failed".
class SystemFault : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ProcessSystem final : public LandingSystem {
 public:
  explicit ProcessSystem(ProcessOptions options) : options_(std::move(options)), name_("exec:" + options_.command) {}
  ProcessSystem(const ProcessSystem&) = delete;
  ProcessSystem& operator=(const ProcessSystem&) = delete;
  ~ProcessSystem() override { stop(true); }

  [[nodiscard]] std::string_view name() const override { return name_; }

  void reset(const SystemSetup& setup) override {
    try {
      if (pid_ <= 0) start();
      const std::string json = protocol::setup_json(setup);
      send("reset", {{json.data(), json.size()}});
      const protocol::Header h = receive(options_.step_timeout_s, "reset");
      if (h.verb != "ready" || !h.sizes.empty()) unexpected(h, "ready");
    } catch (...) {
      stop(false);
      throw;
    }
  }

  SystemOutput update(const SystemInput& input) override {
    try {
      // The frame's buffers go to the socket as they are (no copy).
      const std::string state = protocol::state_json(input);
      std::vector<Bytes> payloads{{state.data(), state.size()}, {}, {}, {}};
      if (input.frame != nullptr) {
        const CameraFrame& f = *input.frame;
        if (hello_.image) payloads[1] = {f.image.pixels.data(), f.image.pixels.size()};
        if (hello_.mask) payloads[2] = {f.mask.data(), f.mask.size()};
        if (hello_.depth) payloads[3] = {f.depth.data(), f.depth.size() * sizeof(float)};
      }
      send("step", payloads);
      const protocol::Header h = receive(options_.step_timeout_s, "step");
      if (h.verb != "command" || h.sizes.size() != 1) unexpected(h, "command");
      const std::string json = payload(h.sizes[0], options_.step_timeout_s);
      try {
        return protocol::parse_output(json, phase_);
      } catch (const protocol::ProtocolError& e) {
        throw SystemFault(std::string("the system answered a bad command: ") + e.what());
      }
    } catch (...) {
      stop(false);
      throw;
    }
  }

 private:
  void start() {
    int fds[2] = {-1, -1};
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0) {
      throw SystemFault(std::string("socketpair: ") + std::strerror(errno));
    }
    const std::string script = "exec " + options_.command;
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0) {
      ::close(fds[0]);
      ::close(fds[1]);
      throw SystemFault(std::string("fork: ") + std::strerror(errno));
    }
    if (pid == 0) {
      // The child: async-signal-safe calls only.
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) ::_exit(126);
      // Its own process group: what it starts (a wrapper's children, a
      // launcher's nodes) is ended with it (stop()).
      if (::setpgid(0, 0) != 0) ::_exit(125);
      // A host app blocks SIGINT/SIGTERM/SIGHUP to wait for them in one
      // thread (apps/app_common.hpp); the system gets the default mask.
      sigset_t none;
      sigemptyset(&none);
      ::sigprocmask(SIG_SETMASK, &none, nullptr);
      ::dup2(fds[1], 0);
      ::dup2(fds[1], 1);
      ::close_range(3, ~0U, 0);
      ::execl("/bin/sh", "sh", "-c", script.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::close(fds[1]);
    (void)::setpgid(pid, pid);    // also here: whichever runs first (EACCES once it has exec'd)
    register_process_group(pid);  // an app ending by a signal kills it too
    fd_ = fds[0];
    pid_ = pgid_ = pid;
    buffer_.clear();
    const std::string version =
        protocol::header("touchdown-system", {static_cast<std::size_t>(kSystemProtocolVersion)});
    send_all({{version.data(), version.size()}});
    const protocol::Header h = receive(options_.start_timeout_s, "hello");
    if (h.verb != "touchdown-system") unexpected(h, "touchdown-system");
    const std::string json = h.sizes.size() == 2 ? payload(h.sizes[1], options_.start_timeout_s) : "";
    try {
      hello_ = protocol::parse_hello(h, json);
    } catch (const protocol::ProtocolError& e) {
      throw SystemFault(e.what());
    }
  }

  // Ends the child: bye and a moment to exit when it is well, then SIGKILL.
  void stop(bool polite) noexcept {
    if (pid_ > 0 && polite && fd_ >= 0) {
      const std::string bye = protocol::header("bye");
      (void)::send(fd_, bye.data(), bye.size(), MSG_NOSIGNAL);
      ::shutdown(fd_, SHUT_WR);
      for (int i = 0; i < 50 && !ended(nullptr); ++i) ::usleep(10000);
    }
    // The whole group, also when the child itself has ended: nothing it
    // started outlives it. The child is reaped only after that, so its pid
    // (the group's id) cannot have gone to another process in between.
    if (pgid_ > 0) {
      ::kill(-pgid_, SIGKILL);
      unregister_process_group(pgid_);
    }
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);  // also when it left its group
      ::waitpid(pid_, nullptr, 0);
    }
    pid_ = pgid_ = -1;
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

  [[noreturn]] void unexpected(const protocol::Header& h, const char* wanted) {
    if (h.verb == "error" && h.sizes.size() == 1) {
      std::string text = payload(std::min<std::size_t>(h.sizes[0], 4096), options_.step_timeout_s);
      throw SystemFault("the system reported an error: " + text);
    }
    throw SystemFault("the system answered '" + h.verb + "' where '" + wanted + "' was due");
  }

  // Whether the child has ended, and how, without reaping it (waitid with
  // WNOWAIT): stop() reaps it once its group is killed.
  bool ended(std::string* how) const {
    if (pid_ <= 0) return false;
    siginfo_t info{};
    if (::waitid(P_PID, static_cast<id_t>(pid_), &info, WEXITED | WNOHANG | WNOWAIT) != 0 || info.si_pid != pid_) {
      return false;
    }
    if (how != nullptr) {
      *how = info.si_code == CLD_EXITED ? "exited with status " + std::to_string(info.si_status)
                                        : "was killed by signal " + std::to_string(info.si_status);
    }
    return true;
  }

  // How the child ended, once it has (waits up to 1 s for it).
  std::string exit_status() const {
    std::string how;
    for (int i = 0; i < 100; ++i) {
      if (ended(&how)) return how;
      ::usleep(10000);
    }
    return "closed its output";
  }

  // Writes the pieces in order, as one stream (sendmsg: no copy into one buffer).
  void send_all(std::vector<Bytes> pieces) {
    const Deadline deadline = after(options_.step_timeout_s);
    std::size_t first = 0;
    while (first < pieces.size()) {
      if (pieces[first].size == 0) {
        ++first;
        continue;
      }
      std::vector<iovec> iov;
      for (std::size_t i = first; i < pieces.size() && iov.size() < 64; ++i) {
        if (pieces[i].size > 0)
          iov.push_back({const_cast<void*>(pieces[i].data), pieces[i].size});  // NOLINT: sendmsg's iovec is not const
      }
      msghdr m{};
      m.msg_iov = iov.data();
      m.msg_iovlen = iov.size();
      const ssize_t n = ::sendmsg(fd_, &m, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        wait_for(POLLOUT, 0, deadline, options_.step_timeout_s, "reading its input");
        continue;
      }
      if (n < 0) {
        throw SystemFault("the system's process " + exit_status() + " (writing to it: " + std::strerror(errno) + ")");
      }
      // Advance past what went out.
      auto left = static_cast<std::size_t>(n);
      while (left > 0 && first < pieces.size()) {
        Bytes& b = pieces[first];
        const std::size_t k = std::min(left, b.size);
        b.data = static_cast<const char*>(b.data) + k;
        b.size -= k;
        left -= k;
        if (b.size == 0) ++first;
      }
    }
  }

  void send(const char* verb, const std::vector<Bytes>& payloads) {
    std::vector<std::size_t> sizes;
    for (const Bytes& p : payloads) sizes.push_back(p.size);
    const std::string head = protocol::header(verb, sizes);
    std::vector<Bytes> pieces{{head.data(), head.size()}};
    pieces.insert(pieces.end(), payloads.begin(), payloads.end());
    send_all(std::move(pieces));
  }

  // Waits for `events` on the socket until the deadline (first `spins`
  // polls that do not sleep: detail::wait_fd).
  // Waits in slices of kEndedCheckSeconds, looking between them whether the
  // child has ended: something it started may hold the socket open, and
  // its end is then the answer, not the timeout.
  void wait_for(short events, int spins, Deadline deadline, double timeout_s, const std::string& what) {
    for (;;) {
      const double left = std::chrono::duration<double>(deadline - Clock::now()).count();
      if (left <= 0) {  // a negative timeout would wait for ever
        throw SystemFault("no answer from the system within " + format_fixed(timeout_s, 1) + " s (while it was " +
                          what + ")");
      }
      bool ready = false;
      try {
        ready = detail::wait_fd(fd_, events, spins, std::min(left, kEndedCheckSeconds));
      } catch (const Error& e) {
        throw SystemFault(e.what());
      }
      if (ready) return;
      spins = 0;
      if (left <= kEndedCheckSeconds) {
        throw SystemFault("no answer from the system within " + format_fixed(timeout_s, 1) + " s (while it was " +
                          what + ")");
      }
      if (std::string how; ended(&how)) throw SystemFault("the system's process " + how + " (while " + what + ")");
    }
  }

  // Reads at least one more byte into buffer_ before the deadline.
  void fill(Deadline deadline, double timeout_s, const std::string& what) {
    char chunk[65536];
    ssize_t n = ::recv(fd_, chunk, sizeof chunk, MSG_DONTWAIT);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      wait_for(POLLIN, kSpins, deadline, timeout_s, what);
      n = ::recv(fd_, chunk, sizeof chunk, MSG_DONTWAIT);
    }
    if (n > 0) {
      buffer_.append(chunk, static_cast<std::size_t>(n));
      return;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return;
    throw SystemFault("the system's process " + exit_status() + " (while " + what + ")");
  }

  protocol::Header receive(double timeout_s, const char* what) {
    const Deadline deadline = after(timeout_s);
    std::size_t eol = 0;
    while ((eol = buffer_.find('\n')) == std::string::npos) {
      if (buffer_.size() >= protocol::kMaxHeader) throw SystemFault("the system's header is over 256 bytes");
      fill(deadline, timeout_s, std::string("answering ") + what);
    }
    const std::string line = buffer_.substr(0, eol);
    buffer_.erase(0, eol + 1);
    try {
      return protocol::parse_header(line);
    } catch (const protocol::ProtocolError& e) {
      throw SystemFault(std::string("the system answered a malformed header: ") + e.what());
    }
  }

  std::string payload(std::size_t n, double timeout_s) {
    if (n > protocol::kMaxJsonPayload)
      throw SystemFault("the system announced a payload of " + std::to_string(n) + " bytes");
    const Deadline deadline = after(timeout_s);
    while (buffer_.size() < n) {
      try {
        fill(deadline, timeout_s, "sending a payload");
      } catch (const SystemFault& e) {
        throw SystemFault(std::string(e.what()) + ": " + std::to_string(buffer_.size()) + " of " + std::to_string(n) +
                          " bytes came");
      }
    }
    std::string p = buffer_.substr(0, n);
    buffer_.erase(0, n);
    return p;
  }

  ProcessOptions options_;
  std::string name_;
  protocol::Hello hello_;
  std::string phase_;
  std::string buffer_;
  pid_t pid_ = -1;
  pid_t pgid_ = -1;  // the child's process group (its pid), until stop()
  int fd_ = -1;
};

}  // namespace

bool ProcessOptions::validate(std::string* why) const {
  const auto bad = [why](const std::string& w) {
    if (why != nullptr) *why = w;
    return false;
  };
  if (command.find_first_not_of(" \t") == std::string::npos) return bad("command: empty");
  if (!(start_timeout_s > 0 && start_timeout_s <= 3600)) return bad("start_timeout_s: must be in (0, 3600] s");
  if (!(step_timeout_s > 0 && step_timeout_s <= 3600)) return bad("step_timeout_s: must be in (0, 3600] s");
  return true;
}

ProcessOptions parse_exec_spec(std::string_view spec) {
  constexpr std::string_view kPrefix = "exec";
  const std::string where(spec);
  const auto colon = spec.find(':');
  if (spec.substr(0, kPrefix.size()) != kPrefix || colon == std::string_view::npos ||
      (colon != kPrefix.size() && spec[kPrefix.size()] != ',')) {
    throw InvalidArgument(where + ": not exec:COMMAND nor exec,KEY=SECONDS,...:COMMAND");
  }
  ProcessOptions o;
  o.command = std::string(spec.substr(colon + 1));
  std::string_view keys = spec.substr(kPrefix.size(), colon - kPrefix.size());
  while (!keys.empty()) {
    keys.remove_prefix(1);  // the ','
    const std::string_view item = keys.substr(0, keys.find(','));
    keys.remove_prefix(item.size());
    const auto eq = item.find('=');
    const std::string key(item.substr(0, eq));
    double* value = key == "step-timeout" ? &o.step_timeout_s : key == "start-timeout" ? &o.start_timeout_s : nullptr;
    if (value == nullptr || eq == std::string_view::npos) {
      throw InvalidArgument(where + ": option '" + std::string(item) +
                            "': the options are step-timeout=SECONDS and start-timeout=SECONDS");
    }
    const std::string_view text = item.substr(eq + 1);
    if (!touchdown::detail::parse_double(text, *value)) {
      throw InvalidArgument(where + ": " + key + ": '" + std::string(text) + "' is not a number");
    }
  }
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument(where + ": " + why);
  return o;
}

std::unique_ptr<LandingSystem> make_process_system(const ProcessOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("exec system: " + why);
  return std::make_unique<ProcessSystem>(options);
}

}  // namespace touchdown::scenario
