#include "touchdown/pose/sim/aruco_dictionary.hpp"

#include <array>
#include <cctype>
#include <mutex>
#include <opencv2/aruco.hpp>

namespace touchdown::pose {
namespace {

// OpenCV 4.6 aruco/dictionary.hpp, enum PREDEFINED_DICTIONARY_NAME, in its order.
constexpr std::array<std::pair<std::string_view, cv::aruco::PREDEFINED_DICTIONARY_NAME>, 21> kNames{{
    {"4X4_50", cv::aruco::DICT_4X4_50},
    {"4X4_100", cv::aruco::DICT_4X4_100},
    {"4X4_250", cv::aruco::DICT_4X4_250},
    {"4X4_1000", cv::aruco::DICT_4X4_1000},
    {"5X5_50", cv::aruco::DICT_5X5_50},
    {"5X5_100", cv::aruco::DICT_5X5_100},
    {"5X5_250", cv::aruco::DICT_5X5_250},
    {"5X5_1000", cv::aruco::DICT_5X5_1000},
    {"6X6_50", cv::aruco::DICT_6X6_50},
    {"6X6_100", cv::aruco::DICT_6X6_100},
    {"6X6_250", cv::aruco::DICT_6X6_250},
    {"6X6_1000", cv::aruco::DICT_6X6_1000},
    {"7X7_50", cv::aruco::DICT_7X7_50},
    {"7X7_100", cv::aruco::DICT_7X7_100},
    {"7X7_250", cv::aruco::DICT_7X7_250},
    {"7X7_1000", cv::aruco::DICT_7X7_1000},
    {"ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
    {"APRILTAG_16h5", cv::aruco::DICT_APRILTAG_16h5},
    {"APRILTAG_25h9", cv::aruco::DICT_APRILTAG_25h9},
    {"APRILTAG_36h10", cv::aruco::DICT_APRILTAG_36h10},
    {"APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11},
}};

// Code counts and cell sizes come from OpenCV's own tables, read once.
const std::array<ArucoDictionaryInfo, kNames.size()>& table() {
  static const auto kTable = [] {
    std::array<ArucoDictionaryInfo, kNames.size()> out{};
    for (std::size_t i = 0; i < kNames.size(); ++i) {
      const auto d = cv::aruco::getPredefinedDictionary(kNames[i].second);
      out[i] = {kNames[i].first, static_cast<int>(kNames[i].second), d->bytesList.rows, d->markerSize};
    }
    return out;
  }();
  return kTable;
}

std::string upper(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

const ArucoDictionaryInfo* find_aruco_dictionary(std::string_view name) {
  std::string key = upper(name);
  if (key.rfind("DICT_", 0) == 0) key.erase(0, 5);
  for (const auto& d : table()) {
    if (upper(d.name) == key) return &d;
  }
  return nullptr;
}

std::vector<std::string> aruco_dictionary_name_list() {
  std::vector<std::string> out;
  out.reserve(kNames.size());
  for (const auto& n : kNames) out.emplace_back(n.first);
  return out;
}

std::string unknown_aruco_dictionary(std::string_view name) {
  std::string known;
  for (const auto& n : kNames) known += (known.empty() ? "" : ", ") + std::string(n.first);
  return "'" + std::string(name) + "' (known: " + known + ")";
}

}  // namespace touchdown::pose
