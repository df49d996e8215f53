#pragma once
/// \file
/// Mesh files through assimp: read STL (ascii/binary), OBJ and PLY; write
/// binary STL (default), ascii STL, PLY (binary or ascii) and OBJ.
#include <array>
#include <filesystem>
#include <string_view>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/mesh.hpp"

namespace touchdown {

enum class MeshFormat { Auto, StlBinary, StlAscii, PlyBinary, PlyAscii, Obj };

template <>
struct EnumNames<MeshFormat> {
  static constexpr std::array<std::string_view, 6> names{"auto",       "stl_binary", "stl_ascii",
                                                         "ply_binary", "ply_ascii",  "obj"};
};
inline std::string_view to_string(MeshFormat format) { return enum_name(format); }

/// Output format from the extension: .stl → binary STL, .ply → binary PLY,
/// .obj → OBJ (no material file). Throws InvalidArgument otherwise.
MeshFormat mesh_format_from_path(const std::filesystem::path& path);

/// Reads every mesh in the file into one indexed triangle mesh (node
/// transforms applied, identical vertices joined). Throws IoError/ParseError
/// naming the file.
TriangleMesh read_mesh(const std::filesystem::path& path);

/// Writes atomically (temporary file + rename).
void write_mesh(const TriangleMesh& mesh, const std::filesystem::path& path, MeshFormat format = MeshFormat::Auto);

}  // namespace touchdown
