#pragma once
/// \file
/// Escaping text for XML (the SVG figures the apps and modules write).
#include <string>
#include <string_view>

namespace touchdown {

/// `text` with the characters XML text and single-quoted attributes cannot
/// hold as they are (& < > ') replaced by their entities.
inline std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace touchdown
