#include "touchdown/core/version.hpp"

namespace touchdown {

std::string version() { return TOUCHDOWN_VERSION_STRING; }

}  // namespace touchdown
