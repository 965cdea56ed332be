// The X server for rendering lives alone in this file: Xlib's macros (None,
// Status, Bool) must not meet VTK's or ParcelScope's names.
//
// VTK 9.1 as packaged in Debian renders through GLX only (no EGL, no OSMesa),
// so every figure needs an X server. When $DISPLAY names none (unset, or
// nothing answers there), the process starts a private Xvfb of its own and
// points $DISPLAY at it before VTK opens a connection; the server is stopped
// when the process ends.
#include <X11/Xlib.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "parcelscope/core/Error.h"
#include "parcelscope/viz/Figures.h"

extern char** environ;

namespace parcelscope::viz {

namespace {

constexpr auto kStartTimeout = std::chrono::seconds(30);
constexpr auto kStopTimeout = std::chrono::seconds(5);

const std::string kNoXvfb =
    "Xvfb (started in its place) is not installed; install the Debian package xvfb (scripts/install-deps.sh "
    "does) or pass --figures 0";

// The last line a failed Xvfb wrote to its log (fd), for the error message.
std::string lastLogLine(int fd) {
  std::string text;
  if (::lseek(fd, 0, SEEK_SET) == 0) {
    char buf[4096];
    for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
  }
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  const std::size_t start = text.find_last_of('\n');
  return start == std::string::npos ? text : text.substr(start + 1);
}

// Stops the server `pid` and reaps it: SIGTERM (Xvfb then removes its lock
// file and socket itself), SIGKILL after kStopTimeout, and then the lock file
// and socket of display `number` are removed here if they still name `pid`.
void stopServer(pid_t pid, int number) {
  if (pid <= 0) return;
  ::kill(pid, SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + kStopTimeout;
  int status = 0;
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid || (r < 0 && errno != EINTR)) return;  // reaped (ECHILD: reaped by someone else)
    if (std::chrono::steady_clock::now() > deadline) break;
    ::usleep(10000);
  }
  ::kill(pid, SIGKILL);
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (number < 0) return;
  const std::string lock = "/tmp/.X" + std::to_string(number) + "-lock";
  char held[32] = {};
  if (FILE* f = std::fopen(lock.c_str(), "r")) {
    const std::size_t n = std::fread(held, 1, sizeof held - 1, f);
    std::fclose(f);
    held[n] = '\0';
    if (std::atol(held) == static_cast<long>(pid)) {
      std::remove(lock.c_str());
      std::remove(("/tmp/.X11-unix/X" + std::to_string(number)).c_str());
    }
  }
}

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// A started Xvfb: its process and display number.
struct Server {
  pid_t pid = -1;
  int number = -1;
};

// Starts `Xvfb -displayfd FD -screen 0 1920x1080x24 -nolisten tcp -terminate`
// and waits until it accepts connections. Xvfb picks a free display number
// itself and writes it to FD once it listens, so processes started side by
// side never race for one. It runs in a process group of its own (Ctrl-C on a
// terminal reaches this process, which then stops it, not the server while a
// figure is being drawn), with -terminate: it also ends by itself when its
// last client leaves, which this process's connection does only when the
// process ends, however it ends (even killed). Throws Error(IO) with `why`
// (why a server of our own is needed) when Xvfb is missing or fails.
Server startServer(const std::string& why) {
  Fd readEnd, writeEnd, log;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw ioError(why + ", and no pipe for Xvfb: " + std::strerror(errno));
  readEnd.fd = fds[0];
  writeEnd.fd = fds[1];
  // Xvfb's messages go to an unnamed temporary file, read back only when it fails.
  const char* tmp = std::getenv("TMPDIR");
  std::string logName = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/parcelscope-xvfb-XXXXXX";
  log.fd = ::mkostemp(logName.data(), O_CLOEXEC);
  if (log.fd >= 0) ::unlink(logName.c_str());

  // The number's descriptor in Xvfb: 3, 4 or 5, whichever is not a source of the copies below.
  int target = 3;
  while (target == writeEnd.fd || target == log.fd) ++target;
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_adddup2(&files, writeEnd.fd, target);  // clears close-on-exec
  if (log.fd >= 0) {
    posix_spawn_file_actions_adddup2(&files, log.fd, STDERR_FILENO);
  } else {
    posix_spawn_file_actions_addopen(&files, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  }
  posix_spawn_file_actions_addopen(&files, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 34))
  // Nothing else this process inherited (pipes of its caller) stays open in the server.
  posix_spawn_file_actions_addclosefrom_np(&files, target + 1);
#endif
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  for (int s : {SIGTERM, SIGINT, SIGHUP, SIGQUIT, SIGPIPE, SIGUSR1}) sigaddset(&defaults, s);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setpgroup(&attributes, 0);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  const std::string fdArgument = std::to_string(target);
  std::vector<std::string> args = {"Xvfb",         "-displayfd", fdArgument, "-screen",   "0",
                                   "1920x1080x24", "-nolisten",  "tcp",      "-terminate"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  Server server;
  const int spawned = ::posix_spawnp(&server.pid, "Xvfb", &files, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  posix_spawnattr_destroy(&attributes);
  if (spawned == ENOENT || spawned == EACCES) throw ioError(why + ", and " + kNoXvfb);
  if (spawned != 0) throw ioError(why + ", and Xvfb cannot be started: " + std::strerror(spawned));
  ::close(writeEnd.fd);  // end of file on the pipe when Xvfb ends without a number
  writeEnd.fd = -1;

  // The number arrives with a newline once the server accepts connections.
  std::string number;
  const auto deadline = std::chrono::steady_clock::now() + kStartTimeout;
  bool ended = false;
  while (number.empty() || number.back() != '\n') {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{readEnd.fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) break;
    char c[16];
    const ssize_t n = ::read(readEnd.fd, c, sizeof c);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ended = true;
      break;
    }
    number.append(c, static_cast<std::size_t>(n));
  }
  if (number.empty() || number.back() != '\n') {
    stopServer(server.pid, -1);
    const std::string said = log.fd >= 0 ? lastLogLine(log.fd) : std::string();
    throw ioError(why + ", and the Xvfb started in its place " +
                  (ended ? std::string("ended") : "did not answer within 30 s") +
                  (said.empty() ? std::string() : " (Xvfb: " + said + ")"));
  }
  server.number = std::atoi(number.c_str());
  return server;
}

// The display of the process: a connection kept open for its whole life (an
// X server such as Xvfb resets, and may drop its authorisation, when its last
// client leaves, which would happen between two figures otherwise), and the
// private server if one was started, stopped at exit. Static: its destructor
// runs after those of the render windows made later (they hold connections
// of their own to the server).
struct ProcessDisplay {
  std::mutex mutex;
  ::Display* connection = nullptr;
  Server server;
  pid_t owner = ::getpid();

  ~ProcessDisplay() {
    if (server.pid <= 0 || ::getpid() != owner) return;  // nothing started, or a forked child
    if (connection != nullptr) XCloseDisplay(connection);
    stopServer(server.pid, server.number);
  }
};

ProcessDisplay& processDisplay() {
  static ProcessDisplay display;
  return display;
}

}  // namespace

void requireDisplay() {
  ProcessDisplay& d = processDisplay();
  std::lock_guard<std::mutex> lock(d.mutex);
  if (d.connection != nullptr) return;
  const char* name = std::getenv("DISPLAY");
  std::string why;
  if (name == nullptr || *name == '\0') {
    why = "rendering figures needs an X server: DISPLAY is not set";
  } else {
    d.connection = XOpenDisplay(name);
    if (d.connection != nullptr) return;
    why = "rendering figures needs an X server: none answers on DISPLAY=" + std::string(name);
  }
  d.server = startServer(why);
  const std::string own = ":" + std::to_string(d.server.number);
  d.connection = XOpenDisplay(own.c_str());
  if (d.connection == nullptr) {
    stopServer(d.server.pid, d.server.number);
    d.server = {};
    throw ioError(why + ", and the Xvfb started in its place on " + own + " refuses connections");
  }
  // Before VTK opens its own connection, which reads DISPLAY.
  ::setenv("DISPLAY", own.c_str(), 1);
}

}  // namespace parcelscope::viz
