#include "touchdown/pose/sim/sequence.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <system_error>
#include <tuple>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::pose {

namespace fs = std::filesystem;

// ---- sequence listing and frames -------------------------------------------

namespace {

// A frame's file name: PREFIX + NUMBER + an image extension (.png, .jpg,
// .jpeg in any case), not a depth image (STEM.depth.png): "000042.png",
// "frame_0001.jpg". The prefix holds no digit at its end (the number is
// every digit before the extension).
struct NumberedName {
  std::string prefix, stem;
  unsigned long long number = 0;
};

bool is_image_extension(std::string ext) {
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

std::optional<NumberedName> numbered_name(const std::string& file) {
  const std::size_t dot = file.rfind('.');
  if (dot == std::string::npos || dot == 0 || !is_image_extension(file.substr(dot))) return std::nullopt;
  const std::string stem = file.substr(0, dot);
  if (stem.size() > 6 && stem.compare(stem.size() - 6, 6, ".depth") == 0) return std::nullopt;
  std::size_t first_digit = stem.size();
  while (first_digit > 0 && stem[first_digit - 1] >= '0' && stem[first_digit - 1] <= '9') --first_digit;
  const std::size_t digits = stem.size() - first_digit;
  if (digits == 0 || digits > 18) return std::nullopt;
  NumberedName n;
  n.prefix = stem.substr(0, first_digit);
  n.stem = stem;
  n.number = std::stoull(stem.substr(first_digit));
  return n;
}

std::string describe_type(int type) {
  const int depth = CV_MAT_DEPTH(type);
  const char* names[] = {"8-bit unsigned", "8-bit signed", "16-bit unsigned", "16-bit signed",
                         "32-bit integer", "32-bit float", "64-bit float",    "16-bit float"};
  const std::string d = depth >= 0 && depth < 8 ? names[depth] : "unknown";
  return d + " with " + std::to_string(CV_MAT_CN(type)) + " channel(s)";
}

// CRC-32 as used by PNG chunks (ISO 3309 polynomial, PNG spec sec. 5.5).
std::uint32_t crc32(const unsigned char* p, std::size_t n) {
  static const auto kTable = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) c = kTable[(c ^ p[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

std::uint32_t be32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

// Checks a PNG's chunk structure and CRCs before decoding, so that a
// truncated or damaged file is one clear error (libpng would print its own
// message on stderr). Returns false if the bytes are not a PNG at all.
bool check_png(const std::vector<unsigned char>& b, const fs::path& path) {
  static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (b.size() < 8 || !std::equal(kSignature, kSignature + 8, b.begin())) return false;
  std::size_t at = 8;
  bool first = true;
  while (true) {
    if (b.size() - at < 12)
      throw ParseError(path.string() + ": truncated PNG (chunk header at byte " + std::to_string(at) + ")");
    const std::uint32_t len = be32(&b[at]);
    if (len > b.size() - at - 12)
      throw ParseError(path.string() + ": truncated PNG (chunk at byte " + std::to_string(at) + " runs past the end)");
    const unsigned char* type = &b[at + 4];
    const std::string name(reinterpret_cast<const char*>(type), 4);
    if (first && name != "IHDR") throw ParseError(path.string() + ": corrupt PNG (first chunk is not IHDR)");
    first = false;
    if (crc32(type, 4 + std::size_t{len}) != be32(&b[at + 8 + len])) {
      throw ParseError(path.string() + ": corrupt PNG (CRC mismatch in " + name + " chunk at byte " +
                       std::to_string(at) + ")");
    }
    at += 12 + std::size_t{len};
    if (name == "IEND") return true;
  }
}

// Reads and decodes an image; IoError when unreadable, ParseError when
// corrupt (cv::imread alone returns an empty Mat for both).
cv::Mat read_image(const fs::path& path) {
  std::vector<unsigned char> bytes;
  {
    auto in = detail::open_for_read(path);  // IoError naming the file when missing or unreadable
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  // imdecode asserts on an empty buffer, in a message of several lines.
  if (bytes.empty()) throw ParseError(path.string() + ": empty file (0 bytes)");
  check_png(bytes, path);
  cv::Mat m;
  try {
    m = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    // e.what() is OpenCV's multi-line report; its condition is one line.
    std::string why = e.err;
    std::replace(why.begin(), why.end(), '\n', ' ');
    throw ParseError(path.string() + ": cannot decode the image (" + why + ")");
  }
  if (m.empty()) throw ParseError(path.string() + ": not a readable image (corrupt or unsupported format)");
  return m;
}

}  // namespace

std::vector<SequenceFrame> list_sequence(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw IoError(dir.string() + ": sequence directory does not exist");
  if (!fs::is_directory(dir, ec)) throw IoError(dir.string() + ": not a directory");
  struct Found {
    NumberedName name;
    fs::path path;
  };
  std::vector<Found> found;
  std::vector<std::string> others;  // for the message when no frame is found
  fs::directory_iterator it(dir, ec);
  if (ec) throw IoError(dir.string() + ": cannot list the directory: " + ec.message());
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    if (ec) throw IoError(dir.string() + ": cannot list the directory: " + ec.message());
    const std::string file = it->path().filename().string();
    std::error_code ec2;
    if (!it->is_regular_file(ec2)) continue;
    if (auto n = numbered_name(file)) {
      found.push_back({std::move(*n), it->path()});
    } else {
      others.push_back(file);
    }
  }
  if (ec) throw IoError(dir.string() + ": cannot list the directory: " + ec.message());
  if (found.empty()) {
    std::sort(others.begin(), others.end());
    std::string listed;
    for (std::size_t i = 0; i < std::min<std::size_t>(others.size(), 5); ++i) listed += (i ? ", " : "") + others[i];
    if (others.size() > 5) listed += ", ...";
    throw ParseError(dir.string() + ": no frames in the sequence directory (" +
                     (others.empty() ? std::string("it is empty") : "found " + listed) +
                     "; expected numbered images: NNNNNN.png, or any PREFIX + number + .png/.jpg such as "
                     "frame_0001.jpg)");
  }
  // One numbering per directory: two prefixes (left_0001.png beside
  // right_0001.png, or a cover0.jpg beside the frames) or two files of one
  // frame (000001.png and 000001.jpg) are refused rather than interleaved.
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
    return std::tie(a.name.number, a.name.stem, a.path) < std::tie(b.name.number, b.name.stem, b.path);
  });
  for (const Found& f : found) {
    if (f.name.prefix != found.front().name.prefix) {
      throw ParseError(dir.string() + ": frames of two numberings (" + found.front().path.filename().string() +
                       " and " + f.path.filename().string() + "): keep one sequence per directory");
    }
  }
  std::vector<SequenceFrame> frames;
  for (std::size_t i = 0; i < found.size(); ++i) {
    if (i > 0 && found[i].name.number == found[i - 1].name.number) {
      throw ParseError(dir.string() + ": two files for frame " + std::to_string(found[i].name.number) + " (" +
                       found[i - 1].path.filename().string() + " and " + found[i].path.filename().string() + ")");
    }
    SequenceFrame f;
    f.name = found[i].name.stem;
    f.colour = found[i].path;
    std::error_code ec2;
    const fs::path depth = dir / (f.name + ".depth.png");
    if (fs::is_regular_file(depth, ec2)) f.depth = depth;
    frames.push_back(std::move(f));
  }
  return frames;
}

void read_frame(const SequenceFrame& frame, BgrImage& colour, DepthImage* depth) {
  const cv::Mat m = read_image(frame.colour);
  const int code = m.type() == CV_8UC3   ? -1
                   : m.type() == CV_8UC1 ? cv::COLOR_GRAY2BGR
                   : m.type() == CV_8UC4 ? cv::COLOR_BGRA2BGR
                                         : -2;
  if (code == -2) {
    throw ParseError(frame.colour.string() + ": unsupported pixel format " + describe_type(m.type()) +
                     " (expected 8-bit BGR, BGRA or grey)");
  }
  colour.resize(m.cols, m.rows);
  cv::Mat dst(m.rows, m.cols, CV_8UC3, colour.pixels.data());
  if (code == -1) {
    m.copyTo(dst);
  } else {
    cv::cvtColor(m, dst, code);
  }
  if (depth == nullptr) return;
  if (!frame.depth) {
    depth->resize(0, 0);
    return;
  }
  const cv::Mat d = read_image(*frame.depth);
  if (d.type() != CV_16UC1) {
    throw ParseError(frame.depth->string() + ": depth must be 16-bit with one channel, got " + describe_type(d.type()));
  }
  if (d.cols != m.cols || d.rows != m.rows) {
    throw ParseError(frame.depth->string() + ": depth is " + std::to_string(d.cols) + "x" + std::to_string(d.rows) +
                     " but colour is " + std::to_string(m.cols) + "x" + std::to_string(m.rows));
  }
  depth->resize(d.cols, d.rows);
  d.copyTo(cv::Mat(d.rows, d.cols, CV_16UC1, depth->pixels.data()));
}

// ---- sequence.yaml -----------------------------------------------------------

std::string sequence_info_to_yaml(const SequenceInfo& info) {
  std::string out = "# How led_pose render made this sequence (docs/formats.md, \"Image sequences\")\n";
  if (info.seed) out += "seed: " + std::to_string(*info.seed) + "\n";
  if (info.aruco) {
    out += "aruco: {dictionary: " + info.aruco->dictionary + ", id: " + std::to_string(info.aruco->marker_id) +
           ", size: " + detail::format_exact(info.aruco->marker_size) + "}\n";
  }
  return out;
}

namespace {

std::uint64_t read_seed(const detail::YamlReader& r, const YAML::Node& n) {
  const std::string text = n.IsScalar() ? std::string(detail::trim(n.Scalar())) : std::string();
  std::uint64_t v = 0;
  const bool digits = !text.empty() && text.size() <= 20 &&
                      std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits || !detail::parse_int(text, v)) r.fail(n, "seed", "expected an integer in [0, 2^64), got '" + text + "'");
  return v;
}

}  // namespace

SequenceInfo parse_sequence_info(std::string_view yaml_text, std::string_view source) {
  const YAML::Node root = detail::load_yaml(yaml_text, source);
  const detail::YamlReader r{source};
  SequenceInfo info;
  if (!root || root.IsNull()) return info;
  try {
    r.only(root, "", {"seed", "aruco"});
    if (root["seed"]) info.seed = read_seed(r, root["seed"]);
    if (const YAML::Node a = root["aruco"]) {
      r.only(a, "aruco.", {"dictionary", "id", "size"});
      ArucoOptions o;
      o.dictionary = r.text(r.child(a, "aruco.", "dictionary"), "aruco.dictionary");
      o.marker_id = r.integer(r.child(a, "aruco.", "id"), "aruco.id");
      o.marker_size = r.number(r.child(a, "aruco.", "size"), "aruco.size");
      std::string why;
      if (!o.validate(&why)) r.fail(a, "aruco", why);
      info.aruco = o;
    }
  } catch (const YAML::Exception& e) {
    throw ParseError(std::string(source) + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  return info;
}

SequenceInfo read_sequence_info(const fs::path& dir) {
  const fs::path path = dir / kSequenceInfoFile;
  std::error_code ec;
  if (!fs::exists(path, ec)) return {};
  return parse_sequence_info(detail::read_text_file(path), path.string());
}

// ---- ground truth JSON lines -------------------------------------------------

// ---- sequence writer -------------------------------------------------------

namespace {

std::string frame_name(std::size_t i) {
  std::string s = std::to_string(i);
  return std::string(6 - std::min<std::size_t>(6, s.size()), '0') + s;
}

void write_png(const fs::path& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(path.string(), image);
  } catch (const cv::Exception& e) {
    throw IoError(path.string() + ": cannot write the image: " + e.what());
  }
  if (!ok) throw IoError(path.string() + ": cannot write the image");
}

// A file write_sequence writes: NNNNNN.png, NNNNNN.depth.png, the ground
// truth, camera and constellation.
bool is_sequence_file(const std::string& name) {
  if (name == "ground_truth.jsonl" || name == "camera.yaml" || name == "constellation.yaml" ||
      name == kSequenceInfoFile) {
    return true;
  }
  const bool six_digits =
      name.size() >= 6 && std::all_of(name.begin(), name.begin() + 6, [](char c) { return c >= '0' && c <= '9'; });
  const std::string rest = six_digits ? name.substr(6) : std::string();
  return rest == ".png" || rest == ".depth.png";
}

// Removes the files of an older sequence in `target` that the new one does
// not replace (its frames beyond the new count), so two sequences never mix;
// any other file is kept.
void remove_stale_sequence_files(const fs::path& target, const std::vector<std::string>& new_files) {
  const std::set<std::string> replaced(new_files.begin(), new_files.end());
  std::error_code ec, file_ec;
  std::vector<fs::path> stale;
  for (const auto& entry : fs::directory_iterator(target, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file(file_ec) && is_sequence_file(name) && !replaced.count(name)) {
      stale.push_back(entry.path());
    }
  }
  if (ec) throw IoError(target.string() + ": cannot list the directory: " + ec.message());
  for (const auto& path : stale) {
    if (!fs::remove(path, ec) || ec) {
      throw IoError(path.string() + ": cannot remove the old sequence's file: " + ec.message());
    }
  }
}

}  // namespace

void write_sequence(const fs::path& out_dir, const CameraModel& camera, const Constellation& constellation,
                    std::span<const TrajectorySample> samples, const RenderOptions& options, std::uint64_t seed,
                    const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (samples.empty()) throw InvalidArgument("write_sequence: no samples to render");
  if (samples.size() > 1000000) throw InvalidArgument("write_sequence: more than 1000000 frames (names are 6 digits)");
  const SyntheticCamera renderer(camera, constellation, options);  // validates

  fs::path target = out_dir.lexically_normal();
  if (!target.has_filename()) target = target.parent_path();
  if (target.empty()) throw InvalidArgument("write_sequence: empty output directory");
  std::error_code ec;
  if (fs::exists(target, ec) && !fs::is_directory(target, ec)) {
    throw IoError(target.string() + ": exists and is not a directory");
  }
  StagedDirectory staged(target);  // removed, with what it holds, unless renamed into place
  const fs::path& staging = staged.path();
  std::vector<std::string> files;
  RenderedFrame frame;
  std::string ground_truth;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Eigen::Isometry3d& T = samples[i].T_camera_body;
    renderer.render(T, motion_blur_start(samples, i), seed, i, frame);
    const std::string name = frame_name(i);
    write_png(staging / (name + ".png"),
              cv::Mat(frame.colour.height, frame.colour.width, CV_8UC3, frame.colour.pixels.data()));
    write_png(staging / (name + ".depth.png"),
              cv::Mat(frame.depth.height, frame.depth.width, CV_16UC1, frame.depth.pixels.data()));
    files.push_back(name + ".png");
    files.push_back(name + ".depth.png");
    GroundTruthSample g;
    g.frame = name;
    g.t_s = samples[i].t;
    g.T_camera_body = T;
    g.leds_visible = frame.led_visible;
    g.marker_visible = frame.marker_visible;
    ground_truth += ground_truth_to_json(g) + "\n";
    if (progress) progress(progress_since(start, i + 1, samples.size(), i));
  }
  detail::write_text_file(staging / "ground_truth.jsonl", ground_truth);
  detail::write_text_file(staging / "camera.yaml", camera_to_yaml(camera));
  detail::write_text_file(staging / "constellation.yaml", constellation_to_yaml(constellation));
  SequenceInfo info;
  info.seed = seed;
  info.aruco.emplace();
  info.aruco->dictionary = options.aruco_dictionary;
  info.aruco->marker_id = options.aruco_id;
  info.aruco->marker_size = options.aruco_size;
  detail::write_text_file(staging / kSequenceInfoFile, sequence_info_to_yaml(info));
  files.insert(files.end(), {"ground_truth.jsonl", "camera.yaml", "constellation.yaml", kSequenceInfoFile});

  // Into place: one rename of the whole directory when the target is new;
  // otherwise file by file (each rename atomic; the ground truth last).
  if (!fs::exists(target, ec)) {
    staged.commit();
    return;
  }
  remove_stale_sequence_files(target, files);
  std::stable_partition(files.begin(), files.end(), [](const std::string& f) { return f != "ground_truth.jsonl"; });
  for (const auto& f : files) {
    fs::rename(staging / f, target / f, ec);
    if (ec) throw IoError((target / f).string() + ": cannot move the finished file into place: " + ec.message());
  }
}

}  // namespace touchdown::pose
