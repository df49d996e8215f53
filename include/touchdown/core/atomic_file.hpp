#pragma once
/// \file
/// Write-to-temporary-then-rename, so that a failed write never leaves a
/// partial output file (docs/architecture.md, "Conventions": outputs and signals).
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace touchdown {

/// Calls `write(tmp)` with a temporary path in the target's directory, then
/// renames it onto `target`. Throws IoError naming `target` when its
/// directory does not exist or the rename fails; if `write` throws, the
/// temporary file is removed and the exception propagates.
void write_file_atomically(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path& tmp)>& write);

/// The output files of one run, written as a whole: each target is checked
/// when it is added, before any work (its directory exists and is writable,
/// it is not a directory, no other output of the run has the same path), and
/// gets a temporary file beside it with the same extension (writers that pick
/// a format by the extension still work), which the caller writes. commit()
/// renames every temporary onto its target; destroyed before commit() (an
/// error on the way), it removes them all, so a failed run leaves no output.
class StagedOutputs {
 public:
  StagedOutputs() = default;
  StagedOutputs(const StagedOutputs&) = delete;
  StagedOutputs& operator=(const StagedOutputs&) = delete;
  ~StagedOutputs();

  /// Checks `target` and returns the temporary path to write it to. Throws
  /// IoError naming `label` (an option such as "--plot", or empty) and the
  /// target.
  std::filesystem::path add(const std::filesystem::path& target, const std::string& label = "");
  /// Renames every temporary that was written onto its target; a target
  /// whose temporary was never created (an output the run did not produce)
  /// is left as it was. Throws IoError.
  void commit();

 private:
  struct Entry {
    std::filesystem::path target, tmp;
    std::filesystem::path identity;  ///< the file `target` names (symlinks and ".." resolved)
    std::string label;
  };
  std::vector<Entry> entries_;
  bool committed_ = false;
};

/// A directory output written as a whole: a hidden staging directory beside
/// `target` (`.NAME.partial-PID-N`), written by the caller, renamed onto
/// `target` by commit(); destroyed before that (an error, an exception),
/// it is removed with what it holds. The target's parent must exist.
class StagedDirectory {
 public:
  /// Throws IoError when the parent of `target` does not exist or the
  /// staging directory cannot be made.
  explicit StagedDirectory(const std::filesystem::path& target);
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;
  ~StagedDirectory();

  [[nodiscard]] const std::filesystem::path& path() const { return staging_; }
  [[nodiscard]] const std::filesystem::path& target() const { return target_; }
  /// Renames the staging directory onto the target, which must not exist.
  /// Throws IoError.
  void commit();

 private:
  std::filesystem::path target_, staging_;
  bool committed_ = false;
};

/// The temporaries (files and staging directories) that outputs of this
/// process are being written to and that no commit has renamed yet:
/// StagedOutputs, write_file_atomically and the sequence writer register
/// theirs for as long as they exist. A program stopped by a signal removes
/// them with remove_live_temporaries() (the apps do, on SIGINT, SIGTERM and
/// SIGHUP: app_common.hpp), so an interrupted run leaves nothing behind.
void register_temporary(const std::filesystem::path& path);
void unregister_temporary(const std::filesystem::path& path);
/// Removes every registered temporary (recursively: a staging directory
/// with what was written into it); returns how many existed. Not
/// async-signal-safe: call it from a thread that waited for the signal.
std::size_t remove_live_temporaries() noexcept;

/// Removes the temporaries a stopped process left beside `target` (named
/// as this file's writers name them: `.NAME.tmp-PID-N...` and
/// `.NAME.partial-PID-N`, with PID a process that no longer runs; killed
/// with SIGKILL, a run cannot clean up). Returns the paths removed. Called
/// by StagedOutputs::add and the sequence writer before they stage.
std::vector<std::filesystem::path> remove_stale_temporaries(const std::filesystem::path& target) noexcept;

}  // namespace touchdown
