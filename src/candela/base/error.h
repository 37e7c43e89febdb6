#pragma once
// The errors candela reports to its user, one type per kind of problem, all derived from
// CandelaError. The command line exits with one status per type (exit_code_for below; docs/cli.md,
// "Exit status") and the Python module raises one exception per type (python/module.cpp). Every throw
// whose message can reach a user throws one of these; an exception of another type that reaches the
// command line's main() is a bug, as an InternalError is.
//
// Every problem with user input is a SceneError whose message names the place:
//   "scene.pbrt:12:5: Shape \"sphere\": \"radius\" must be a positive float"
//   "scene.json: at /shapes/3/radius: expected a positive number, got -1"
#include <fmt/format.h>

#include <exception>
#include <functional>
#include <stdexcept>
#include <string>

namespace candela {

struct SourceLocation {
  std::string file;      // as the user named it
  int line = 0;          // 1-based; 0 = unknown
  int column = 0;        // 1-based; 0 = unknown
  std::string key_path;  // JSON pointer for JSON scenes, e.g. /shapes/3/radius

  std::string to_string() const {
    std::string s = file.empty() ? "<input>" : file;
    if (line > 0) s += fmt::format(":{}", line);
    if (line > 0 && column > 0) s += fmt::format(":{}", column);
    if (!key_path.empty()) s += fmt::format(": at {}", key_path);
    return s;
  }
};

// Names the place of entry i of a description list (a texture, a material) in messages; empty
// = the entries' places are not known.
using EntryPlace = std::function<std::string(size_t index)>;

// The base of every error candela reports; what() is the whole message, printed as it is.
class CandelaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A problem in the scene input (a scene file, a dict given to load_dict): the message names the file
// and line, or the JSON pointer, of the offending entry.
class SceneError : public CandelaError {
 public:
  using CandelaError::CandelaError;
};

template <typename... Args>
[[noreturn]] void throw_scene_error(const SourceLocation& where, fmt::format_string<Args...> format,
                                    Args&&... args) {
  throw SceneError(where.to_string() + ": " + fmt::format(format, std::forward<Args>(args)...));
}

// A problem inside a data file candela reads: a mesh, a volume grid or an image a scene references,
// a checkpoint to resume from, a part to merge. A reader that knows the file's name puts it in the
// message; one that does not (a mesh or grid parser) leaves it to its caller, which adds the file
// and the scene entry that named it and throws a SceneError, so every failure reaches the user as
// one message.
class FileContentError : public CandelaError {
 public:
  using CandelaError::CandelaError;
};

template <typename... Args>
[[noreturn]] void fail_file_content(fmt::format_string<Args...> format, Args&&... args) {
  throw FileContentError(fmt::format(format, std::forward<Args>(args)...));
}

// A request the renderer refuses: a command-line flag or Python keyword out of range, an unknown
// name, settings that exclude each other, an output that cannot be written found out before
// rendering. Messages name the flag as the command line spells it ("--spp: ..."); the Python module
// names its keyword instead.
class UsageError : public CandelaError {
 public:
  using CandelaError::CandelaError;
};

// A scene parameter name that the scene does not have (scene/parameters.h); Python raises KeyError.
class UnknownParameterError : public UsageError {
 public:
  using UsageError::UsageError;
};

// A file candela cannot write once it has rendered or converted: an image, a checkpoint, a part, a
// converted JSON scene (disk full, permission, a directory gone). The message names the file.
class OutputError : public CandelaError {
 public:
  using CandelaError::CandelaError;
};

// A broken invariant: a bug in candela (or a library or system call failing where it must not), never
// a problem with what the user gave.
class InternalError : public CandelaError {
 public:
  using CandelaError::CandelaError;
};

// The command line's exit status for each outcome (docs/cli.md, "Exit status").
inline constexpr int kExitBadInput = 1;      // SceneError, FileContentError
inline constexpr int kExitUsage = 2;         // UsageError, and flags the command line cannot parse
inline constexpr int kExitInterrupted = 3;   // SIGINT/SIGTERM: the partial image (and checkpoint) written
inline constexpr int kExitOutput = 4;        // OutputError
inline constexpr int kExitInternal = 70;     // InternalError or any other exception: a bug (EX_SOFTWARE)
inline constexpr int kExitSecondSignal = 130;  // a second SIGINT/SIGTERM: exit at once, nothing more written

// The exit status of a command that failed with `error`: kExitBadInput, kExitUsage, kExitOutput or
// kExitInternal.
int exit_code_for(const std::exception& error);

}  // namespace candela
