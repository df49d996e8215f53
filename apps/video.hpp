#pragma once
// A video file of an app's overlaid frames (landing_scenario, landing_mission):
// OpenCV's writer on a staged temporary, the container picked by the
// extension (.mp4: mpeg-4 part 2; .avi: MJPEG).
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown::app {

class VideoFile {
 public:
  /// Writes to `tmp`, the staged temporary of `path` (same extension).
  VideoFile(const std::filesystem::path& tmp, const std::string& path, double fps, int width, int height) {
    const int fourcc = tmp.extension() == ".avi" ? cv::VideoWriter::fourcc('M', 'J', 'P', 'G')
                                                 : cv::VideoWriter::fourcc('m', 'p', '4', 'v');
    if (!writer_.open(tmp.string(), fourcc, fps, cv::Size(width, height))) {
      throw IoError(path + ": cannot open a video writer (" + tmp.extension().string() + ")");
    }
  }
  void write(const cv::Mat& image) { writer_.write(image); }
  void finish() { writer_.release(); }

 private:
  cv::VideoWriter writer_;
};

}  // namespace touchdown::app
