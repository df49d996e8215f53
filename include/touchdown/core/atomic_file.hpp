#pragma once
/// \file
/// Write-to-temporary-then-rename, so that a failed write never leaves a
/// partial output file (DESIGN.md, app conventions).
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

}  // namespace touchdown
