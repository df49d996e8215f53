#pragma once
/// \file
/// Library version.
#include <string>

namespace touchdown {

/// The library's version, "MAJOR.MINOR.PATCH".
std::string version();

}  // namespace touchdown
