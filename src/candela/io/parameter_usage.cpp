#include "candela/io/parameter_usage.h"

#include <algorithm>

#include "candela/base/nearest_name.h"

namespace candela {

void ParameterUsage::give(std::string name, SourceLocation where) {
  given_.push_back({std::move(name), std::move(where), false});
}

bool ParameterUsage::ask(std::string_view name) {
  if (std::find(asked_.begin(), asked_.end(), name) == asked_.end()) asked_.emplace_back(name);
  bool found = false;
  for (Parameter& p : given_)
    if (p.name == name) p.used = found = true;
  return found;
}

void ParameterUsage::mark_used(std::string_view name) {
  for (Parameter& p : given_)
    if (p.name == name) p.used = true;
}

void ParameterUsage::mark_used_at(size_t index) { given_.at(index).used = true; }

bool ParameterUsage::was_given(std::string_view name) const {
  return std::any_of(given_.begin(), given_.end(), [&](const Parameter& p) { return p.name == name; });
}

std::string ParameterUsage::asked_list() const {
  std::string list;
  for (const std::string& name : asked_) list += (list.empty() ? "" : ", ") + name;
  return list;
}

std::string ParameterUsage::did_you_mean(std::string_view name) const {
  std::vector<std::string_view> names(asked_.begin(), asked_.end());
  return candela::did_you_mean(name, names);
}

const ParameterUsage::Parameter* ParameterUsage::first_unused() const {
  for (const Parameter& p : given_)
    if (!p.used) return &p;
  return nullptr;
}

}  // namespace candela
