#pragma once
// The one table of ArUco/AprilTag dictionaries (internal to
// touchdown::pose_sim): the renderer draws the marker the baseline detects,
// so both must accept exactly the same names.
#include <opencv2/aruco.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace touchdown::pose::detail {

struct ArucoDictionaryInfo {
  std::string_view name;  // canonical spelling, without "DICT_"
  cv::aruco::PREDEFINED_DICTIONARY_NAME id;
  int codes = 0;  // markers in the dictionary
  int bits = 0;   // marker side in cells, without the black border
};

/// `name` in any letter case, with or without the "DICT_" prefix; nullptr
/// when unknown.
const ArucoDictionaryInfo* find_aruco_dictionary(std::string_view name);

/// All names, in OpenCV's PREDEFINED_DICTIONARY_NAME order.
std::vector<std::string> aruco_dictionary_name_list();

/// "'NAME' (known: 4X4_50, ...)" for an unknown-dictionary message.
std::string unknown_aruco_dictionary(std::string_view name);

}  // namespace touchdown::pose::detail
