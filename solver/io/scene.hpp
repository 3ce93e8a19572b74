#pragma once
// Scene JSON -> typed problem: the one place where a scene's names become types. Every error
// names the JSON pointer of the offending value; all errors are collected, not only the first,
// up to kMaxSceneIssues.
#include <algorithm>
#include <cstddef>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "solver/io/quantities.hpp"
#include "solver/problem/problem.hpp"
#include "solver/stepping/load_stepping.hpp"

namespace grip {

struct SceneIssue {
  std::string pointer;  // JSON pointer of the offending value
  std::string detail;   // a plain sentence
};

// The most problems a scene's reading collects: reading stops at the next one (8 MB of equal
// supports made 1.7 million problems and a peak of 1.3 GB to list 100 of them).
inline constexpr std::size_t kMaxSceneIssues = 100;

class SceneErrors : public std::runtime_error {
 public:
  // `more`: reading stopped at kMaxSceneIssues problems with more to find.
  explicit SceneErrors(std::vector<SceneIssue> issues, bool more = false);
  const std::vector<SceneIssue>& issues() const { return issues_; }
  bool more() const { return more_; }

 private:
  std::vector<SceneIssue> issues_;
  bool more_ = false;
};

// What the result keeps: fields only for the chosen steps, and only the chosen kinds.
struct OutputOptions {
  static inline const std::vector<std::string> kAllFields = {"nodes", "elements", "contact_points", "reactions",
                                                             "history"};
  std::vector<std::string> fields = kAllFields;
  bool wants(const std::string& field) const { return std::find(fields.begin(), fields.end(), field) != fields.end(); }
  std::vector<Quantity> quantities;  // the scene's `outputs`, computed at every converged step
};

struct GmshMesh;

// A mesh that a scene names by reference, body.mesh.gmsh {"file": ...} or {"id": ...}: the
// caller resolves it (grip solve reads a file relative to the scene, the service an upload by
// its id). Throws std::invalid_argument with a sentence that names the file or the id.
using MeshResolver = std::function<std::shared_ptr<const GmshMesh>(const nlohmann::json& ref)>;

// The gmsh tags of a body whose mesh came from a file: per node and per element of the body,
// so that a user finds their node and element (result mesh.gmsh, the VTK arrays gmsh_tag).
struct FileMeshTags {
  int body = 0;  // index in the scene's bodies (0 for `body`)
  std::vector<std::size_t> nodes, elements;
};

// An axisymmetric body (docs/algorithm.md#axisymmetric): the nodes on the axis whose u_r = 0 the
// reader imposed (those the scene's supports did not hold already).
struct AxisHold {
  int body = 0;  // index in the scene's bodies (0 for `body`)
  std::vector<int> nodes;
};

struct Scene {
  nlohmann::json effective;  // the scene with every default filled in
  Problem problem;
  std::vector<std::string> load_cases;  // names, in the order of LoadStep::factors
  std::vector<LoadStep> steps;
  SteppingParams params;  // params.record_fields: the steps whose fields are kept
  OutputOptions output;
  std::vector<FileMeshTags> file_meshes;
  std::vector<AxisHold> axis_holds;  // one per axisymmetric body
};

// Throws SceneErrors listing the problems found (at most kMaxSceneIssues). Without `meshes` a
// scene that names a mesh file is refused (body.mesh.gmsh names the pointer).
Scene read_scene(const nlohmann::json& scene, const MeshResolver& meshes = {});
// read_scene without the schema stage, for a scene that passed read_scene before and was
// stored unchanged (the service's workers read their job's scene again: the schema check was
// a quarter of that read). The reader's own checks still run and throw SceneErrors.
Scene read_checked_scene(const nlohmann::json& scene, const MeshResolver& meshes = {});
// Mesh files are read relative to the scene file's folder.
Scene read_scene_file(const std::string& path);

}  // namespace grip
