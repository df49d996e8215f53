#pragma once
/// \file
/// The one table of ArUco/AprilTag dictionaries (touchdown::pose_sim): the
/// renderers draw the marker the detectors find, and the scenario format
/// and the search's repairs check ids against its sizes, so all accept
/// exactly the same names.
#include <string>
#include <string_view>
#include <vector>

namespace touchdown::pose {

struct ArucoDictionaryInfo {
  std::string_view name;  // canonical spelling, without "DICT_"
  int opencv_id = 0;      // OpenCV's cv::aruco::PREDEFINED_DICTIONARY_NAME value
  int codes = 0;          // markers in the dictionary
  int bits = 0;           // marker side in cells, without the black border
};

/// `name` in any letter case, with or without the "DICT_" prefix; nullptr
/// when unknown.
const ArucoDictionaryInfo* find_aruco_dictionary(std::string_view name);

/// All names, in OpenCV's PREDEFINED_DICTIONARY_NAME order.
std::vector<std::string> aruco_dictionary_name_list();

/// "'NAME' (known: 4X4_50, ...)" for an unknown-dictionary message.
std::string unknown_aruco_dictionary(std::string_view name);

}  // namespace touchdown::pose
