#pragma once
// The rule every scene reader (and the command line's integrator flags) applies: each parameter an
// entity is given must be read by it, or the input is rejected, as pbrt-v4's ReportUnused and
// Mitsuba's unqueried-property check do. A misspelt optional parameter would otherwise be ignored.
//
// A reader records each parameter the entity was given (`give`, with its place in the file) and
// each name it asks for (`ask`, given or not). Once the entity is built, `first_unused` names the
// first given parameter nothing asked for, and `asked_list` says what was asked for, for the
// message ("parameters read here: ...").
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "candela/base/error.h"

namespace candela {

class ParameterUsage {
 public:
  struct Parameter {
    std::string name;
    SourceLocation where;
    bool used = false;
  };

  // Records a parameter the entity was given. Names may repeat (pbrt's parameter lists allow it):
  // asking for a name uses every copy.
  void give(std::string name, SourceLocation where);

  // Records that the reader asked for `name`; marks the given copies used. True when it was given.
  bool ask(std::string_view name);

  // Marks a given parameter used without recording it as read here (a parameter consumed on the
  // entity's behalf, e.g. by a default it inherits).
  void mark_used(std::string_view name);
  // Marks the parameter given `index`-th (from 0) used, and no other copy of its name (Mitsuba's
  // nested objects, taken by their kind rather than asked for by name).
  void mark_used_at(size_t index);

  bool was_given(std::string_view name) const;
  const std::vector<Parameter>& given() const { return given_; }
  const std::vector<std::string>& asked() const { return asked_; }
  std::string asked_list() const;  // "a, b, c" in the order first asked
  // " (did you mean \"x\"?)" for the asked-for name nearest to `name`, or "" (base/nearest_name.h).
  std::string did_you_mean(std::string_view name) const;

  // The first parameter, in the order given, that nothing asked for.
  const Parameter* first_unused() const;

 private:
  std::vector<Parameter> given_;
  std::vector<std::string> asked_;
};

}  // namespace candela
