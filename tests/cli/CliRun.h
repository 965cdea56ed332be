#pragma once
// Running the shipped `parcelscope` command as a user does, for the CLI tests.
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace parcelscope::test {

struct CliRun {
  int code;            ///< exit code; -1 when the process did not exit normally
  std::string output;  ///< stdout and stderr
};

/// Runs a shell command line, collecting stdout and stderr.
inline CliRun runShell(const std::string& commandLine) {
  const std::string cmd = commandLine + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  CliRun r{-1, ""};
  if (!pipe) return r;
  char buf[4096];
  while (std::size_t n = fread(buf, 1, sizeof buf, pipe)) r.output.append(buf, n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

/// Runs `parcelscope ARGS` through the shell (ARGS quoted as needed), prefixed by `env`
/// (e.g. "env -u DISPLAY").
inline CliRun runCli(const std::string& args, const std::string& env = "") {
  return runShell(env + (env.empty() ? "" : " ") + "'" + PARCELSCOPE_CLI + "' " + args);
}

inline std::string slurp(const std::string& path) {
  std::stringstream s;
  s << std::ifstream(path).rdbuf();
  return s.str();
}

}  // namespace parcelscope::test
