// Runs a tool the way a user's shell would, for the tests of the command-line tools.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace cvo_test {

struct CommandOutput {
  int status = -1;     // the exit status; -1 when the command did not exit normally
  std::string output;  // standard output and standard error together
};

// Runs `command` with sh, its standard error joined to its standard output.
inline CommandOutput runCommand(const std::string& command) {
  CommandOutput result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return result;
  std::array<char, 4096> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe))
    result.output += buffer.data();
  const int status = pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace cvo_test
