#pragma once
/// \file
/// Minimal image types (the LED pose pipeline, the test world's camera), so that public headers stay
/// free of OpenCV: non-owning views (wrap any buffer, e.g. a cv::Mat's data
/// or a camera driver's frame) and owning images that reuse their storage.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace touchdown {

/// 8-bit BGR pixels, row-major; `stride` is the distance between rows in bytes.
struct BgrImageView {
  const std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride = 0;
  [[nodiscard]] const std::uint8_t* row(int y) const { return data + static_cast<std::ptrdiff_t>(y) * stride; }
};

/// 8-bit grey pixels, row-major; `stride` is the distance between rows in bytes.
struct GrayImageView {
  const std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride = 0;
  [[nodiscard]] const std::uint8_t* row(int y) const { return data + static_cast<std::ptrdiff_t>(y) * stride; }
};

/// 16-bit depth, row-major; `stride` in elements; 0 = no measurement.
struct DepthImageView {
  const std::uint16_t* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride = 0;
  [[nodiscard]] const std::uint16_t* row(int y) const { return data + static_cast<std::ptrdiff_t>(y) * stride; }
};

/// An owning BGR image; resize() keeps the allocation when the size repeats.
struct BgrImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;
  void resize(int w, int h) {
    width = w;
    height = h;
    pixels.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  }
  [[nodiscard]] BgrImageView view() const { return {pixels.data(), width, height, std::ptrdiff_t{3} * width}; }
  [[nodiscard]] std::uint8_t* row(int y) {
    return pixels.data() + static_cast<std::size_t>(y) * 3 * static_cast<std::size_t>(width);
  }
};

/// An owning 16-bit depth image.
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> pixels;
  void resize(int w, int h) {
    width = w;
    height = h;
    pixels.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  }
  [[nodiscard]] bool empty() const { return pixels.empty(); }
  [[nodiscard]] DepthImageView view() const { return {pixels.data(), width, height, width}; }
  [[nodiscard]] std::uint16_t* row(int y) {
    return pixels.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
  }
};

}  // namespace touchdown
