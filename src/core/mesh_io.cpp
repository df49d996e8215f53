// Mesh files through assimp (Open Asset Import Library, assimp.org docs:
// Importer::ReadFile post-processing flags, Exporter::Export format ids).
#include "touchdown/core/mesh_io.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cctype>
#include <memory>
#include <string>

#include "io_util.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown {
namespace {

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r')) s.pop_back();
  return s;
}

const char* assimp_format_id(MeshFormat f) {
  switch (f) {
    case MeshFormat::StlBinary:
      return "stlb";
    case MeshFormat::StlAscii:
      return "stl";
    case MeshFormat::PlyBinary:
      return "plyb";
    case MeshFormat::PlyAscii:
      return "ply";
    case MeshFormat::Obj:
      return "objnomtl";
    case MeshFormat::Auto:
      break;
  }
  return "stlb";
}

}  // namespace

MeshFormat mesh_format_from_path(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".stl") return MeshFormat::StlBinary;
  if (ext == ".ply") return MeshFormat::PlyBinary;
  if (ext == ".obj") return MeshFormat::Obj;
  throw InvalidArgument(path.string() + ": unknown mesh format '" + ext + "' (expected .stl, .ply or .obj)");
}

TriangleMesh read_mesh(const std::filesystem::path& path) {
  { auto probe = detail::open_for_read(path); }  // uniform "cannot open" errors
  Assimp::Importer importer;
  // Keep points and lines out of the scene; we want triangles only.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                                              aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (scene == nullptr) {
    throw ParseError(path.string() + ": cannot read mesh: " + one_line(importer.GetErrorString()));
  }
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      mesh.vertices.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      mesh.triangles.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  if (mesh.triangles.empty()) throw ParseError(path.string() + ": mesh has no triangles");
  return mesh;
}

void write_mesh(const TriangleMesh& mesh, const std::filesystem::path& path, MeshFormat format) {
  if (format == MeshFormat::Auto) format = mesh_format_from_path(path);
  if (mesh.triangles.empty()) throw InvalidArgument(path.string() + ": refusing to write a mesh without triangles");

  // The aiScene owns everything below and frees it in its destructor.
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode();
  scene->mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene->mNumMaterials = 1;
  scene->mMeshes = new aiMesh* [1] { new aiMesh() };
  scene->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
  scene->mRootNode->mNumMeshes = 1;

  aiMesh* am = scene->mMeshes[0];
  am->mMaterialIndex = 0;
  am->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  am->mNumVertices = static_cast<unsigned>(mesh.vertices.size());
  am->mVertices = new aiVector3D[am->mNumVertices];
  for (unsigned i = 0; i < am->mNumVertices; ++i) {
    const auto& v = mesh.vertices[i];
    am->mVertices[i] = aiVector3D(v.x(), v.y(), v.z());
  }
  am->mNumFaces = static_cast<unsigned>(mesh.triangles.size());
  am->mFaces = new aiFace[am->mNumFaces];
  for (unsigned i = 0; i < am->mNumFaces; ++i) {
    const auto& t = mesh.triangles[i];
    am->mFaces[i].mNumIndices = 3;
    am->mFaces[i].mIndices = new unsigned[3]{t[0], t[1], t[2]};
  }

  write_file_atomically(path, [&](const std::filesystem::path& tmp) {
    Assimp::Exporter exporter;
    if (exporter.Export(scene.get(), assimp_format_id(format), tmp.string()) != AI_SUCCESS) {
      throw IoError(path.string() + ": cannot write mesh: " + one_line(exporter.GetErrorString()));
    }
  });
}

}  // namespace touchdown
