#pragma once
// Running the candela command line from tests: a shell command's exit status and output, a file's
// bytes, and a scratch directory per test.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace candela::testing {

struct CommandResult {
  int exit_code;       // -1 when the shell did not exit normally
  std::string output;  // stdout and stderr together
};

// Runs `command` with /bin/sh, its stderr joined to its stdout.
inline CommandResult run_command(const std::string& command) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), pipe)) out.append(buf.data(), n);
  int status = pclose(pipe);
  // UBSan's reports (.ci/sanitizers) go to the program's stderr, and the program then exits with status
  // 1, which a test that expects the program to fail would take for its error: they fail the test here.
  // (ASan's and TSan's reports go to files that the scripts check.)
  EXPECT_EQ(out.find(": runtime error: "), std::string::npos) << command << ":\n" << out;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// The bytes of `file` ("" when it cannot be read).
inline std::string file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A new empty directory under the system's temporary directory, named after `prefix`, this process
// and the running test, so tests running at once never share one.
inline std::filesystem::path fresh_test_directory(const std::string& prefix) {
  std::filesystem::path dir = std::filesystem::temp_directory_path() /
                              (prefix + "_" + std::to_string(getpid()) + "_" +
                               ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace candela::testing
