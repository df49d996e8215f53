#pragma once
// yaml-cpp helpers shared by the YAML config readers (internal).
#include <yaml-cpp/yaml.h>

#include <string>
#include <string_view>

#include "touchdown/core/error.hpp"

namespace touchdown::detail {

/// Parses YAML text; syntax errors become ParseError "source:line: invalid YAML: ...".
inline YAML::Node load_yaml(std::string_view text, std::string_view source) {
  try {
    return YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    throw ParseError(std::string(source) + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
}

}  // namespace touchdown::detail
