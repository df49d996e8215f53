#include "touchdown/core/version.hpp"

#include "touchdown/core/version_defs.hpp"

namespace touchdown {

std::string version() { return TOUCHDOWN_VERSION; }

}  // namespace touchdown
