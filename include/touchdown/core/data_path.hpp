#pragma once
/// \file
/// Where a file named inside another file is found. A mission names its
/// airframe (`drone.airframe: ../airframes/quad180.yaml`) relative to
/// itself; a bundled mission copied elsewhere loses that neighbour, so a
/// relative name that is not beside the file is looked for in touchdown's
/// data directories too, and a miss names every place tried.
#include <filesystem>
#include <string>
#include <vector>

namespace touchdown {

/// The data directories searched after the referring file's own, in
/// order: $TOUCHDOWN_DATA when set, the installed one
/// (`<prefix>/share/touchdown`), and the source tree's `data/` this
/// library was built from. Only those that exist are listed.
[[nodiscard]] std::vector<std::filesystem::path> data_directories();

/// Resolves `name`, as written in a file that lives in `base` (the
/// directory of the referring file). An absolute name is taken as it is.
/// A relative one is tried beside the file first; then, in each data
/// directory, as `name` without its leading `./` and `../` parts and as
/// `kind_dir/filename` (kind_dir: "airframes" for an airframe; empty for
/// none). Throws IoError when no candidate is a regular file:
/// "NAME: cannot open: no such file (tried A, B, C)".
[[nodiscard]] std::filesystem::path resolve_data_file(const std::filesystem::path& base, const std::string& name,
                                                      const std::string& kind_dir = "");

}  // namespace touchdown
