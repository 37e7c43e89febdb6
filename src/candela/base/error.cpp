#include "candela/base/error.h"

namespace candela {

int exit_code_for(const std::exception& error) {
  if (dynamic_cast<const SceneError*>(&error) || dynamic_cast<const FileContentError*>(&error)) return kExitBadInput;
  if (dynamic_cast<const UsageError*>(&error)) return kExitUsage;
  if (dynamic_cast<const OutputError*>(&error)) return kExitOutput;
  return kExitInternal;
}

}  // namespace candela
