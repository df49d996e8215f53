#pragma once
/// \file
/// Write-to-temporary-then-rename, so that a failed write never leaves a
/// partial output file (DESIGN.md, app conventions).
#include <filesystem>
#include <functional>

namespace touchdown {

/// Calls `write(tmp)` with a temporary path in the target's directory, then
/// renames it onto `target`. Throws IoError naming `target` when its
/// directory does not exist or the rename fails; if `write` throws, the
/// temporary file is removed and the exception propagates.
void write_file_atomically(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path& tmp)>& write);

}  // namespace touchdown
