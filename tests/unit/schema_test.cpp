// The JSON Schemas in schemas/ against the documents grip reads and writes: every example
// scene validates, invalid scenes are reported at the right pointer (and, where the reader
// checks the same rule, the reader agrees), and the events, results and job documents the
// solver and the service produce validate.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "solver/io/result.hpp"
#include "solver/io/schema_validation.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::example_scene;

std::string listed(const std::vector<SceneIssue>& issues) {
  std::string s;
  for (const auto& i : issues) s += "\n  " + i.pointer + ": " + i.detail;
  return s.empty() ? " (none)" : s;
}

const fs::path kSchemas = fs::path(GRIP_SOURCE_DIR) / "schemas";

json read_json(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

// A small plane-strain block pressed onto a rigid flat by its prescribed top displacement.
json continuum_scene() {
  return json::parse(R"({
    "body": {
      "model": "continuum",
      "kinematics": "linear",
      "material": {"young": 1000, "poisson": 0.3},
      "mesh": {"rectangle": {"origin": [0, 0], "size": [4, 1], "divisions": [4, 1]}},
      "supports": [{"set": "top", "fix": ["x", "y"], "values": {"y": -0.01}}]
    },
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [10, -0.001], "to": [-10, -0.001]}}],
    "steps": 1
  })");
}

json example_or_continuum(const std::string& name) {
  return name == "continuum" ? continuum_scene() : example_scene(name);
}

// The reader's issues with a scene; when it reads it, none, and (for a valid scene) the
// effective scene it writes, every default filled in, must validate too.
// `file`: read as grip solve reads it (mesh files relative to it), else the JSON alone.
std::vector<SceneIssue> reader_issues(const json& scene, bool valid = true, const fs::path& file = {}) {
  try {
    const Scene read = file.empty() ? read_scene(scene) : read_scene_file(file.string());
    const auto effective = validate_against(read.effective, SchemaName::scene);
    if (valid) EXPECT_TRUE(effective.empty()) << "effective scene:" << listed(effective);
    return {};
  } catch (const SceneErrors& e) {
    return e.issues();
  }
}

TEST(SchemaFiles, EmbeddedTextsAreTheFilesInSchemas) {
  for (SchemaName which : {SchemaName::scene, SchemaName::event, SchemaName::result, SchemaName::job}) {
    const fs::path file = kSchemas / (std::string(schema_file_stem(which)) + ".schema.json");
    SCOPED_TRACE(file.string());
    ASSERT_TRUE(fs::exists(file));
    EXPECT_TRUE(json::parse(schema_text(which)) == read_json(file)) << "the embedded copy is stale: rebuild";
  }
}

TEST(SchemaScene, EveryExampleValidatesAndReads) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kSchemas / "examples")) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().filename().string());
    const json scene = read_json(entry.path());
    const auto issues = validate_against(scene, SchemaName::scene);
    EXPECT_TRUE(issues.empty()) << listed(issues);
    const auto read = reader_issues(scene, true, entry.path());
    EXPECT_TRUE(read.empty()) << "the reader says" << listed(read);
    ++count;
  }
  EXPECT_GE(count, 2);
}

TEST(SchemaScene, ContinuumSceneValidatesAndReads) {
  const json scene = continuum_scene();
  const auto issues = validate_against(scene, SchemaName::scene);
  EXPECT_TRUE(issues.empty()) << listed(issues);
  const auto read = reader_issues(scene);
  EXPECT_TRUE(read.empty()) << "the reader says" << listed(read);
}

// Valid variants of the examples: the schema must not be stricter than the readers.
struct ValidScene {
  const char* what;
  const char* base;
  const char* patch;
  bool reader_reads;  // false: the reader rejects it wrongly (see the report of the schema work)
};

const ValidScene kValidScenes[] = {
    {"steps as a list of load factors", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/steps", "value": [0.5, 1.0, 0.75]}])", true},
    {"stages with two load cases, a motion list and a friction override", "beam-on-cylinder",
     R"([{"op": "remove", "path": "/steps"},
         {"op": "add", "path": "/body/loads/-", "value": {"node": 40, "force": [10, 0], "case": "shear"}},
         {"op": "add", "path": "/obstacles/0/motion", "value": [{"translation": [0, 1], "case": "lift"}]},
         {"op": "add", "path": "/stages", "value": [
           {"steps": 2, "factors": {"main": 1}, "description": "press"},
           {"steps": 2, "factors": {"shear": 1, "lift": 0.5}, "friction": {"cylinder": 0.1}}]}])",
     true},
    {"a support that turns a set (rotation)", "sliding-block",
     R"([{"op": "replace", "path": "/body/supports/0", "value": {"set": "top", "rotation": {"about": [0, 0], "angle": 0.001}, "case": "press"}}])",
     true},
    {"prescribed support values and a moment", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/body/supports/0", "value": {"node": 0, "fix": ["u", "w", "theta"], "values": {"theta": 0.01}}},
         {"op": "add", "path": "/body/loads/0/moment", "value": 5}])",
     true},
    {"linear kinematics, a segment obstacle and an arc obstacle", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/body/kinematics", "value": "linear"},
         {"op": "replace", "path": "/obstacles/0/shape", "value": {"type": "segment", "from": [40, -1], "to": [-10, -1]}},
         {"op": "add", "path": "/obstacles/-", "value": {"name": "roller", "friction": 0,
           "shape": {"type": "arc", "centre": [20, -11], "radius": 10, "start_angle": 45, "end_angle": 135}}}])",
     true},
    {"uzawa on the paper's loop, Newton and cut limits", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/solver", "value": {"contact": {"method": "uzawa", "uzawa_alpha": 0.5, "loop": "paper",
           "max_iterations": 1000, "max_tau_passes": 10, "tau_tolerance": 1e-6, "reach": 5},
           "newton": {"max_iterations": 20}, "max_cuts": 3}}])",
     true},
    {"acceleration levels", "beam-on-cylinder",
     R"([{"op": "add", "path": "/solver/contact/acceleration", "value": {"n": 4, "epsilon": "warmup"}}])", true},
    {"automatic acceleration", "beam-on-cylinder",
     R"([{"op": "add", "path": "/solver/contact/acceleration", "value": {"n": "auto"}}])", true},
    {"the penalty method", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/solver/contact", "value": {"method": "penalty", "penalty": {"normal": 1e6, "factor": 10}}}])",
     true},
    {"output of chosen steps and fields", "beam-on-cylinder",
     R"([{"op": "add", "path": "/output", "value": {"steps": [1, 2], "fields": ["nodes", "history"]}}])", true},
    {"output of the last step", "beam-on-cylinder", R"([{"op": "add", "path": "/output", "value": {"steps": "last"}}])",
     true},
    {"a membrane with loads and prescribed values", "sheet-stretching",
     R"([{"op": "add", "path": "/body/loads", "value": [{"node": 15, "force": [0, -1], "case": "main"}]},
         {"op": "replace", "path": "/body/supports/1", "value": {"node": 30, "fix": ["x", "y"], "values": {"x": 0.1}}},
         {"op": "add", "path": "/body/width", "value": 2}])",
     true},
    {"a membrane on a polyline", "sheet-stretching",
     R"([{"op": "replace", "path": "/body/mesh", "value": {"nodes": [[0, 0], [20, 0], [40, 0], [59.18, 0]]}},
         {"op": "replace", "path": "/body/supports/1/node", "value": 3}])",
     true},
    {"a continuum half-disc", "continuum",
     R"([{"op": "replace", "path": "/body/mesh", "value": {"half_disc": {"centre": [0, 1], "radius": 1, "divisions": [4, 2]}}},
         {"op": "replace", "path": "/body/supports/0/set", "value": "diameter"}])",
     true},
    {"a continuum mesh given node by node, with a traction", "continuum",
     R"([{"op": "replace", "path": "/body/mesh", "value": {"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "elements": [[0, 1, 2, 3]],
           "sets": {"bottom": [0, 1], "top": [2, 3]}}},
         {"op": "add", "path": "/body/contact_set", "value": "bottom"},
         {"op": "replace", "path": "/body/supports", "value": [{"set": "top", "fix": ["y"], "values": {"y": -0.01}},
                                                                 {"node": 3, "fix": ["x"]}]},
         {"op": "add", "path": "/body/loads", "value": [{"set": "top", "traction": [0.1, 0]}]}])",
     true},
    {"a continuum of q9 elements in plane stress", "continuum",
     R"([{"op": "add", "path": "/body/element", "value": "q9"}, {"op": "add", "path": "/body/analysis", "value": "plane_stress"},
         {"op": "add", "path": "/body/material/law", "value": "saint_venant_kirchhoff"}])",
     true},
    {"a continuum of generated t6 elements", "continuum", R"([{"op": "add", "path": "/body/element", "value": "t6"}])",
     true},
    {"a continuum of two t6 given node by node", "continuum",
     R"([{"op": "replace", "path": "/body/mesh", "value": {"nodes": [[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0], [1, 0.5], [0.5, 0.5], [0.5, 1], [0, 0.5]],
           "elements": [[0, 1, 2, 4, 5, 6], [0, 2, 3, 6, 7, 8]], "sets": {"bottom": [0, 4, 1], "top": [2, 7, 3]}}},
         {"op": "add", "path": "/body/element", "value": "t6"},
         {"op": "add", "path": "/body/contact_set", "value": "bottom"}])",
     true},
};

TEST(SchemaScene, ValidVariantsValidate) {
  for (const ValidScene& c : kValidScenes) {
    SCOPED_TRACE(c.what);
    const json scene = example_or_continuum(c.base).patch(json::parse(c.patch));
    const auto issues = validate_against(scene, SchemaName::scene);
    EXPECT_TRUE(issues.empty()) << listed(issues);
    const auto read = reader_issues(scene);
    EXPECT_EQ(read.empty(), c.reader_reads) << "the reader says" << listed(read);
  }
}

// Leaves of a document by pointer; arrays ([x, y], lists) and empty objects are leaves.
void leaves(const json& j, const std::string& at, std::map<std::string, json>& out) {
  if (!j.is_object() || j.empty()) {
    out[at] = j;
    return;
  }
  for (const auto& [k, v] : j.items()) leaves(v, at + "/" + k, out);
}

TEST(SchemaScene, EveryDefaultTheReaderFillsInIsTheSchemasDefault) {
  std::vector<json> scenes = {example_scene("beam-on-cylinder"), example_scene("sheet-stretching"), continuum_scene()};
  for (const ValidScene& c : kValidScenes)
    if (c.reader_reads) scenes.push_back(example_or_continuum(c.base).patch(json::parse(c.patch)));
  int checked = 0;
  for (const json& scene : scenes) {
    const json effective = read_scene(scene).effective;
    std::map<std::string, json> added;
    leaves(effective, "", added);
    for (const auto& [pointer, value] : added) {
      if (scene.contains(json::json_pointer(pointer))) continue;
      SCOPED_TRACE(pointer);
      const auto fallback = schema_default(effective, SchemaName::scene, pointer);
      // Defaults the schema can only describe: "obstacle<i>", "bottom" or "arc", and cev's real
      // solves (held where a body has plasticity).
      const bool described = pointer.rfind("/obstacles/", 0) == 0 && pointer.size() > 5 &&
                                 pointer.compare(pointer.size() - 5, 5, "/name") == 0 ||
                             pointer == "/body/contact_set" || pointer == "/solver/contact/real_solve";
      if (described) {
        EXPECT_FALSE(fallback.has_value());
        continue;
      }
      ASSERT_TRUE(fallback.has_value()) << "the reader fills in " << value << "; the schema has no default";
      EXPECT_EQ(*fallback, value);
      ++checked;
    }
  }
  EXPECT_GT(checked, 40);
}

TEST(SchemaScene, DefaultsFollowTheModel) {
  json beam = example_scene("beam-on-cylinder");
  beam["body"].erase("kinematics");
  EXPECT_EQ(schema_default(beam, SchemaName::scene, "/body/kinematics"), json("von_karman"));
  EXPECT_EQ(schema_default(continuum_scene(), SchemaName::scene, "/body/kinematics"), json("finite"));
  EXPECT_EQ(schema_default(beam, SchemaName::scene, "/solver/contact/acceleration/n"), json("inf"));
  EXPECT_EQ(schema_default(beam, SchemaName::scene, "/body/material/young"), std::nullopt);
}

// Every key a scene can hold says what it is.
void expect_described(const json& schema, const std::string& at) {
  if (schema.is_array()) {
    for (size_t i = 0; i < schema.size(); ++i) expect_described(schema[i], at + "/" + std::to_string(i));
    return;
  }
  if (!schema.is_object()) return;
  for (const auto& [key, sub] : schema.items()) {
    if (key == "if") continue;  // conditions
    if (key == "properties")
      for (const auto& [name, property] : sub.items()) {
        const bool declares = property.contains("type") || property.contains("enum") ||
                              (property.contains("allOf") && !property.contains("not"));
        if (declares)
          EXPECT_TRUE(property.contains("description")) << at << "/properties/" << name << " has no description";
      }
    expect_described(sub, at + "/" + key);
  }
}

TEST(SchemaFiles, EveryPropertyHasADescription) {
  for (SchemaName which : {SchemaName::scene, SchemaName::event, SchemaName::result, SchemaName::job}) {
    SCOPED_TRACE(schema_file_stem(which));
    expect_described(json::parse(schema_text(which)), "");
  }
}

TEST(SchemaScene, ValidatesFromManyThreadsAtOnce) {
  json bad = example_scene("beam-on-cylinder");
  bad["body"]["material"]["poisson"] = 0.62;
  std::vector<std::thread> threads;
  std::atomic<int> wrong{0};
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 20; ++i) {
        const auto issues = validate_against(bad, SchemaName::scene);
        if (issues.size() != 1 || issues[0].pointer != "/body/material/poisson") ++wrong;
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(wrong.load(), 0);
}

// How the reader treats the same scene.
enum class Reader {
  same_pointer,  // rejects it, with an issue at the same pointer
  accepts,       // accepts it (unknown keys: the reader ignores them; listed in the report)
};

struct InvalidScene {
  const char* what;
  const char* base;   // an example's name, or "continuum"
  const char* patch;  // RFC 6902 JSON Patch applied to it
  const char* pointer;
  const char* detail;  // expected substring of the issue's detail
  Reader reader;
};

const InvalidScene kInvalidScenes[] = {
    {"Poisson's ratio above 0.5", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/body/material/poisson", "value": 0.62}])", "/body/material/poisson",
     "0.62 is not below 0.5", Reader::same_pointer},
    {"a misspelt key of the body", "beam-on-cylinder",
     R"([{"op": "add", "path": "/body/materal", "value": {"young": 1}}])", "/body/materal",
     "is not a known key (expected one of \"description\", \"kinematics\", \"loads\", \"material\"", Reader::accepts},
    {"a misspelt top-level key", "beam-on-cylinder", R"([{"op": "add", "path": "/solvr", "value": {}}])", "/solvr",
     "is not a known key", Reader::accepts},
    {"a key of another model", "beam-on-cylinder", R"([{"op": "add", "path": "/body/thickness", "value": 1}])",
     "/body/thickness", "is not a known key", Reader::accepts},
    {"a missing material", "beam-on-cylinder", R"([{"op": "remove", "path": "/body/material"}])", "/body/material",
     "is required", Reader::same_pointer},
    {"a body that is not an object (and no rule about the body's model fires)", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/body", "value": 5}])", "/body", "5 is not an object", Reader::same_pointer},
    {"a missing body", "beam-on-cylinder", R"([{"op": "remove", "path": "/body"}])", "/body", "is required",
     Reader::same_pointer},
    {"Young's modulus as a string", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/body/material/young", "value": "210000"}])", "/body/material/young",
     "\"210000\" is not a number", Reader::same_pointer},
    {"an unknown model", "beam-on-cylinder", R"([{"op": "replace", "path": "/body/model", "value": "beam"}])",
     "/body/model",
     "\"beam\" is not one of \"timoshenko_beam\", \"reissner_beam\", \"rigid_plastic_membrane\", \"continuum\"",
     Reader::same_pointer},
    {"an unknown kinematics", "beam-on-cylinder", R"([{"op": "replace", "path": "/body/kinematics", "value": "vk"}])",
     "/body/kinematics", "\"vk\" is not one of \"von_karman\", \"linear\"", Reader::same_pointer},
    {"a fractional element count", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/body/mesh/elements", "value": 2.5}])", "/body/mesh/elements",
     "2.5 is not an integer", Reader::same_pointer},
    {"a support with both fix and rotation", "sliding-block",
     R"([{"op": "add", "path": "/body/supports/0/rotation", "value": {"about": [0, 0], "angle": 0.001}}])",
     "/body/supports/0", "needs exactly one of \"fix\" (components, with values) and \"rotation\"",
     Reader::same_pointer},
    {"a rotation with values", "sliding-block",
     R"([{"op": "replace", "path": "/body/supports/0", "value": {"set": "top", "rotation": {"about": [0, 0], "angle": 0.001}, "values": {"x": 1}}}])",
     "/body/supports/0/values", "goes with \"fix\"", Reader::same_pointer},
    {"a rotation without its angle", "sliding-block",
     R"([{"op": "replace", "path": "/body/supports/0", "value": {"set": "top", "rotation": {"about": [0, 0]}}}])",
     "/body/supports/0/rotation/angle", "is required", Reader::same_pointer},
    {"a support dof the beam does not have", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/body/supports/0/fix/2", "value": "v"}])", "/body/supports/0/fix/2",
     "\"v\" is not one of \"u\", \"w\", \"theta\"", Reader::same_pointer},
    {"a load applied at an unknown place", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/body/loads/0/at", "value": "middle"}])", "/body/loads/0/at",
     "is not one of \"centre\", \"upper\", \"lower\"", Reader::same_pointer},
    {"a negative radius", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/obstacles/0/shape/radius", "value": -50}])", "/obstacles/0/shape/radius",
     "-50 is not positive", Reader::same_pointer},
    {"a centre that is not a pair", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/obstacles/0/shape/centre", "value": [0]}])", "/obstacles/0/shape/centre",
     "must be a pair of numbers [x, y]", Reader::same_pointer},
    {"an unknown shape", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/obstacles/0/shape/type", "value": "square"}])", "/obstacles/0/shape/type",
     "\"square\" is not one of \"circle\", \"segment\", \"arc\", \"profile\"", Reader::same_pointer},
    {"a key of another shape", "beam-on-cylinder",
     R"([{"op": "add", "path": "/obstacles/0/shape/start_angle", "value": 0}])", "/obstacles/0/shape/start_angle",
     "is not a known key (expected one of \"centre\", \"radius\", \"type\")", Reader::accepts},
    {"negative friction", "beam-on-cylinder", R"([{"op": "replace", "path": "/obstacles/0/friction", "value": -0.1}])",
     "/obstacles/0/friction", "-0.1 is negative", Reader::same_pointer},
    {"no obstacles", "beam-on-cylinder", R"([{"op": "replace", "path": "/obstacles", "value": []}])", "/obstacles",
     "has 0 items; at least 1 needed", Reader::same_pointer},
    {"a misspelt key in a list of motions", "beam-on-cylinder",
     R"([{"op": "add", "path": "/obstacles/0/motion", "value": [{"translaton": [0, -1]}]}])",
     "/obstacles/0/motion/0/translaton", "is not a known key (expected one of \"case\", \"translation\")",
     Reader::accepts},
    {"zero steps", "beam-on-cylinder", R"([{"op": "replace", "path": "/steps", "value": 0}])", "/steps", "0 is below 1",
     Reader::same_pointer},
    {"steps as a string", "beam-on-cylinder", R"([{"op": "replace", "path": "/steps", "value": "20"}])", "/steps",
     "\"20\" is not an integer or an array", Reader::same_pointer},
    {"steps together with stages", "beam-on-cylinder",
     R"([{"op": "add", "path": "/stages", "value": [{"steps": 2, "factors": {"main": 1}}]}])", "/steps",
     "cannot be given together with stages", Reader::same_pointer},
    {"a stage without factors", "beam-on-cylinder",
     R"([{"op": "remove", "path": "/steps"}, {"op": "add", "path": "/stages", "value": [{"steps": 2}]}])",
     "/stages/0/factors", "is required", Reader::same_pointer},
    {"a relative tolerance of 1.5", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/solver/contact/tolerance", "value": 1.5}])", "/solver/contact/tolerance",
     "1.5 is not below 1", Reader::same_pointer},
    {"an unknown contact method", "beam-on-cylinder",
     R"([{"op": "replace", "path": "/solver/contact/method", "value": "lagrange"}])", "/solver/contact/method",
     "\"lagrange\" is not one of \"cev\", \"uzawa\", \"penalty\"", Reader::same_pointer},
    {"a negative reach", "beam-on-cylinder", R"([{"op": "add", "path": "/solver/contact/reach", "value": -1}])",
     "/solver/contact/reach", "-1 is negative", Reader::same_pointer},
    {"an unknown output step selection", "beam-on-cylinder",
     R"([{"op": "add", "path": "/output", "value": {"steps": "first"}}])", "/output/steps",
     "must be \"all\", \"last\" or a list of step numbers", Reader::same_pointer},
    {"an unknown output field", "beam-on-cylinder",
     R"([{"op": "add", "path": "/output", "value": {"fields": ["nodes", "stress"]}}])", "/output/fields/1",
     "\"stress\" is not one of \"nodes\", \"elements\", \"contact_points\"", Reader::same_pointer},
    {"an acceleration level above 64", "beam-on-cylinder",
     R"([{"op": "add", "path": "/solver/contact/acceleration", "value": {"n": 100}}])",
     "/solver/contact/acceleration/n", "must be \"inf\", \"auto\" or an integer from 1 to 64", Reader::same_pointer},
    {"an unknown acceleration level", "beam-on-cylinder",
     R"([{"op": "add", "path": "/solver/contact/acceleration", "value": {"n": "infinite"}}])",
     "/solver/contact/acceleration/n", "must be \"inf\", \"auto\" or an integer from 1 to 64", Reader::same_pointer},
    {"max_cuts out of range", "beam-on-cylinder", R"([{"op": "add", "path": "/solver/max_cuts", "value": 31}])",
     "/solver/max_cuts", "31 is above 30", Reader::same_pointer},
    {"a profile piece without its radius", "sheet-stretching",
     R"([{"op": "remove", "path": "/obstacles/1/shape/pieces/1/radius"}])", "/obstacles/1/shape/pieces/1/radius",
     "is required", Reader::same_pointer},
    {"a profile piece of an unknown type", "sheet-stretching",
     R"([{"op": "replace", "path": "/obstacles/1/shape/pieces/0/type", "value": "line"}])",
     "/obstacles/1/shape/pieces/0/type", "\"line\" is not one of \"segment\", \"arc\"", Reader::same_pointer},
    {"a membrane without a start", "sheet-stretching", R"([{"op": "remove", "path": "/solver/start"}])",
     "/solver/start", "is required for a rigid_plastic_membrane", Reader::same_pointer},
    {"a start of zero depth", "sheet-stretching", R"([{"op": "replace", "path": "/solver/start/value", "value": 0.0}])",
     "/solver/start/value", "must be a non-zero number", Reader::same_pointer},
    {"a hardening exponent of 1", "sheet-stretching",
     R"([{"op": "replace", "path": "/body/material/n", "value": 1.0}])", "/body/material/n", "1.0 is not below 1",
     Reader::same_pointer},
    {"a Hill exponent of 1", "sheet-stretching", R"([{"op": "replace", "path": "/body/material/M", "value": 1}])",
     "/body/material/M", "1 is not above 1", Reader::same_pointer},
    {"a misspelt key of a membrane mesh", "sheet-stretching",
     R"([{"op": "add", "path": "/body/mesh/spacing", "value": 2}])", "/body/mesh/spacing",
     "is not a known key (expected one of \"elements\", \"length\", \"origin\")", Reader::accepts},
    {"a membrane support with a beam dof", "sheet-stretching",
     R"([{"op": "replace", "path": "/body/supports/0/fix/0", "value": "theta"}])", "/body/supports/0/fix/0",
     "\"theta\" is not one of \"x\", \"y\"", Reader::same_pointer},
    {"a continuum support naming a set and a node", "continuum",
     R"([{"op": "add", "path": "/body/supports/0/node", "value": 0}])", "/body/supports/0",
     "needs exactly one of \"set\" (a node set's name) and \"node\" (a node id)", Reader::same_pointer},
    {"a continuum mesh with a rectangle and a half-disc", "continuum",
     R"([{"op": "add", "path": "/body/mesh/half_disc", "value": {"radius": 1, "divisions": [4, 2]}}])", "/body/mesh",
     "needs exactly one of \"nodes\" (with \"elements\"), \"rectangle\", \"half_disc\" and \"gmsh\"",
     Reader::same_pointer},
    {"a t6 element of four nodes", "continuum",
     R"([{"op": "replace", "path": "/body/mesh", "value": {"nodes": [[0, 0], [1, 0], [1, 1], [0, 1]], "elements": [[0, 1, 2, 3]],
           "sets": {"bottom": [0, 1], "top": [2, 3]}}},
         {"op": "add", "path": "/body/element", "value": "t6"},
         {"op": "add", "path": "/body/contact_set", "value": "bottom"}])",
     "/body/mesh/elements/0", "must list 6 node ids (t6)", Reader::same_pointer},
    {"a q8 element of nine nodes", "continuum",
     R"([{"op": "replace", "path": "/body/mesh", "value": {"nodes": [[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0], [1, 0.5], [0.5, 1], [0, 0.5], [0.5, 0.5]],
           "elements": [[0, 1, 2, 3, 4, 5, 6, 7, 8]], "sets": {"bottom": [0, 4, 1]}}},
         {"op": "add", "path": "/body/element", "value": "q8"},
         {"op": "add", "path": "/body/contact_set", "value": "bottom"}])",
     "/body/mesh/elements/0", "must list 8 node ids (q8)", Reader::same_pointer},
    {"q4_bbar with finite kinematics", "continuum",
     R"([{"op": "add", "path": "/body/element", "value": "q4_bbar"}, {"op": "remove", "path": "/body/kinematics"}])",
     "/body/element", "is implemented for linear kinematics", Reader::same_pointer},
    {"a continuum Poisson's ratio of -1", "continuum",
     R"([{"op": "add", "path": "/body/material/poisson", "value": -1}])", "/body/material/poisson",
     "-1 is not above -1", Reader::same_pointer},
    {"an odd half-disc division", "continuum",
     R"([{"op": "replace", "path": "/body/mesh", "value": {"half_disc": {"radius": 1, "divisions": [3, 2]}}}])",
     "/body/mesh/half_disc/divisions/0", "must be an even integer", Reader::same_pointer},
};

TEST(SchemaScene, InvalidScenesAreReportedAtTheirPointer) {
  for (const InvalidScene& c : kInvalidScenes) {
    SCOPED_TRACE(c.what);
    const json scene = example_or_continuum(c.base).patch(json::parse(c.patch));
    const auto issues = validate_against(scene, SchemaName::scene);
    const bool found = std::any_of(issues.begin(), issues.end(), [&](const SceneIssue& i) {
      return i.pointer == c.pointer && i.detail.find(c.detail) != std::string::npos;
    });
    EXPECT_TRUE(found) << "expected " << c.pointer << ": ..." << c.detail << "...; got" << listed(issues);
    EXPECT_EQ(issues.size(), 1u) << listed(issues);
    // No wrapper ("Failed to validate ...") reaches the caller.
    for (const auto& i : issues) EXPECT_EQ(i.detail.find("Failed to validate"), std::string::npos) << i.detail;

    // read_scene runs the schema first, so it reports the same pointer whether or not the
    // readers alone would have caught it (c.reader records which).
    const auto read = reader_issues(scene, false);
    EXPECT_TRUE(std::any_of(read.begin(), read.end(), [&](const SceneIssue& i) { return i.pointer == c.pointer; }))
        << "read_scene says" << listed(read);
  }
}

TEST(SchemaScene, EveryErrorIsReportedOnceInPointerOrder) {
  json scene = example_scene("beam-on-cylinder");
  scene["steps"] = 0;
  scene["body"]["material"]["poisson"] = 0.62;
  scene["body"]["materal"] = 1;
  scene["body"]["mezh"] = 1;
  scene["obstacles"][0]["shape"]["radius"] = -1;
  scene["obstacles"].push_back({{"shape", {{"type", "segment"}, {"from", {0, 0}}}}});
  for (int i = 0; i < 11; ++i) scene["body"]["loads"].push_back({{"node", 1}, {"at", "side"}});
  const auto issues = validate_against(scene, SchemaName::scene);
  std::vector<std::string> pointers;
  for (const auto& i : issues) pointers.push_back(i.pointer);
  // Sorted by pointer, array indices as numbers: /body/loads/2 before /body/loads/10.
  EXPECT_EQ(pointers,
            (std::vector<std::string>{"/body/loads/1/at", "/body/loads/2/at", "/body/loads/3/at", "/body/loads/4/at",
                                      "/body/loads/5/at", "/body/loads/6/at", "/body/loads/7/at", "/body/loads/8/at",
                                      "/body/loads/9/at", "/body/loads/10/at", "/body/loads/11/at", "/body/materal",
                                      "/body/material/poisson", "/body/mezh", "/obstacles/0/shape/radius",
                                      "/obstacles/1/shape/to", "/steps"}))
      << listed(issues);
  EXPECT_EQ(validate_against(scene, SchemaName::scene).size(), issues.size());
}

TEST(SchemaScene, KeysWithSlashesAndTildesAreEscapedInPointers) {
  json scene = example_scene("beam-on-cylinder");
  scene["body"]["a/b~c"] = 1;
  const auto issues = validate_against(scene, SchemaName::scene);
  ASSERT_EQ(issues.size(), 1u) << listed(issues);
  EXPECT_EQ(issues[0].pointer, "/body/a~1b~0c");
}

TEST(SchemaScene, ANonObjectSceneIsReportedAtTheRoot) {
  const auto issues = validate_against(json::array(), SchemaName::scene);
  ASSERT_EQ(issues.size(), 1u) << listed(issues);
  EXPECT_EQ(issues[0].pointer, "/");
  EXPECT_EQ(issues[0].detail, "[] is not an object");
}

// ---- what the solver produces

struct Produced {
  std::vector<json> events;
  json result;
};

Produced solve_with_events(json scene) {
  Scene s = read_scene(scene);
  Produced out;
  SteppingObserver observer;
  observer.step_started = [&](int step, double lf) { out.events.push_back(step_started_event(step, lf)); };
  observer.iteration = [&](const IterationEvent& ev) { out.events.push_back(iteration_event(ev)); };
  observer.step_finished = [&](const StepRecord& rec) {
    out.events.push_back(step_finished_event(s.problem, rec, s.output));
  };
  const RunResult run = run_load_steps(s.problem, s.steps, s.params, observer);
  // The terminal event as `grip solve --events` and the service write it.
  out.events.push_back(run.completed ? json{{"type", "job_finished"}}
                                     : job_failed_event(run.failure, run.reason, run.failure_step));
  out.result = result_json(s, run);
  return out;
}

void expect_valid(const json& doc, SchemaName which) {
  const auto issues = validate_against(doc, which);
  EXPECT_TRUE(issues.empty()) << schema_file_stem(which) << ":" << listed(issues) << "\nin "
                              << doc.dump().substr(0, 400);
}

TEST(SchemaEvents, EveryEventAndTheResultOfTheBeamExampleValidate) {
  json scene = example_scene("beam-on-cylinder");
  scene["steps"] = 3;
  const Produced p = solve_with_events(scene);
  std::map<std::string, int> types;
  for (const json& ev : p.events) {
    ++types[ev["type"]];
    expect_valid(ev, SchemaName::event);
    // As streamed: through JSON text.
    expect_valid(json::parse(ev.dump()), SchemaName::event);
  }
  EXPECT_EQ(types["step_started"], 3);
  EXPECT_EQ(types["step_finished"], 3);
  EXPECT_GT(types["iteration"], 3);
  EXPECT_EQ(types["job_finished"], 1);
  expect_valid(p.result, SchemaName::result);
  expect_valid(json::parse(p.result.dump()), SchemaName::result);
}

TEST(SchemaEvents, FailedStepsAndJobsValidate) {
  json scene = example_scene("beam-on-cylinder");
  scene["steps"] = 1;
  scene["solver"]["contact"]["max_iterations"] = 1;
  scene["solver"]["max_cuts"] = 0;
  const Produced p = solve_with_events(scene);
  ASSERT_EQ(p.events.back()["type"], "job_failed") << p.events.back();
  for (const json& ev : p.events) expect_valid(ev, SchemaName::event);
  expect_valid(p.result, SchemaName::result);
  expect_valid(job_failed_event(FailureKind::dismissed, "dismissed", 0), SchemaName::event);
}

TEST(SchemaEvents, TheMembraneAndContinuumResultsValidate) {
  json sheet = example_scene("sheet-stretching");
  sheet["steps"] = 2;
  sheet["obstacles"][0]["motion"]["translation"] = json::array({0, -2});
  const Produced membrane = solve_with_events(sheet);
  for (const json& ev : membrane.events) expect_valid(ev, SchemaName::event);
  expect_valid(membrane.result, SchemaName::result);
  const Produced block = solve_with_events(continuum_scene());
  for (const json& ev : block.events) expect_valid(ev, SchemaName::event);
  expect_valid(block.result, SchemaName::result);
}

// A body held only by contact: held_by_contact, rigid_motion, and the step that fails because
// no equilibrium can carry its load.
TEST(SchemaEvents, TheResultOfABodyHeldByContactValidates) {
  const Produced p = solve_with_events(testing::block_under_shear());
  for (const json& ev : p.events) expect_valid(ev, SchemaName::event);
  expect_valid(p.result, SchemaName::result);
  EXPECT_EQ(p.result["effects"]["held_by_contact"].size(), 3u);
  EXPECT_TRUE(p.result["steps"][0].contains("rigid_motion"));
}

struct InvalidDocument {
  const char* what;
  SchemaName schema;
  const char* document;
  const char* pointer;
  const char* detail;
};

const InvalidDocument kInvalidDocuments[] = {
    {"an unknown event type", SchemaName::event, R"({"type": "step_begun", "step": 1})", "/type",
     "\"step_begun\" is not one of \"step_started\", \"iteration\", \"step_finished\", \"job_finished\", "
     "\"job_failed\""},
    {"an iteration without its contact error", SchemaName::event,
     R"({"type": "iteration", "step": 1, "pass": 1, "m": 0, "trials": 1, "inner_iterations": 0, "halvings": 0,
         "n": "inf", "alpha": 1, "v_inf": 0, "open": 0, "stick": 0, "slip": 0, "newton_iterations": 2, "elapsed_ms": 1})",
     "/v2", "is required"},
    {"a failed step without its reason", SchemaName::event,
     R"({"type": "step_finished", "step": 1, "load_factor": 1, "converged": false, "tau_passes": 1,
         "contact_iterations": 3, "newton_iterations": 9, "seconds": 0.1, "stage": 0, "factors": [1],
         "failure": {"kind": "contact_budget", "message": "x", "step": 1}})",
     "/reason", "is required"},
    {"a finished step without converged (and no rule about the reason fires)", SchemaName::event,
     R"({"type": "step_finished", "step": 1, "load_factor": 1, "tau_passes": 1,
         "contact_iterations": 3, "newton_iterations": 9, "seconds": 0.1, "stage": 0, "factors": [1]})",
     "/converged", "is required"},
    {"a job failure without its reason", SchemaName::event,
     R"({"type": "job_failed", "failure": {"kind": "dismissed", "message": "x", "step": 0}})", "/reason",
     "is required"},
    {"an extra field in an event", SchemaName::event, R"({"type": "job_finished", "seconds": 1})", "/seconds",
     "is not a known key"},
    {"an unknown job status", SchemaName::job,
     R"({"jobID": "x", "processID": "contact2d", "type": "process", "status": "done", "message": "",
         "created": "2024-05-01T10:00:00.000Z", "updated": "2024-05-01T10:00:00.000Z", "progress": 0,
         "nodes": 41, "steps": 20, "steps_completed": 0, "attempts": 1, "links": []})",
     "/status", "is not one of \"accepted\", \"running\", \"successful\", \"failed\", \"dismissed\""},
    {"progress above 100", SchemaName::job,
     R"({"jobID": "x", "processID": "contact2d", "type": "process", "status": "running", "message": "",
         "created": "2024-05-01T10:00:00.000Z", "updated": "2024-05-01T10:00:00.000Z", "progress": 101,
         "nodes": 41, "steps": 20, "steps_completed": 0, "attempts": 1, "links": []})",
     "/progress", "101 is above 100"},
};

TEST(SchemaDocuments, InvalidEventsAndJobsAreReportedAtTheirPointer) {
  for (const InvalidDocument& c : kInvalidDocuments) {
    SCOPED_TRACE(c.what);
    const auto issues = validate_against(json::parse(c.document), c.schema);
    ASSERT_EQ(issues.size(), 1u) << listed(issues);
    EXPECT_EQ(issues[0].pointer, c.pointer) << listed(issues);
    EXPECT_NE(issues[0].detail.find(c.detail), std::string::npos) << listed(issues);
  }
}

TEST(SchemaJob, JobDocumentsOfEveryStateValidate) {
  const json running = json::parse(R"({
    "jobID": "0f8e2a52-4d0e-4c9a-9b3e-6f2d1c0b7a11", "processID": "contact2d", "type": "process",
    "status": "running", "message": "step 3 of 20, ||v||_2 = 1.234e-06",
    "created": "2024-05-01T10:00:00.000Z", "started": "2024-05-01T10:00:00.120Z",
    "updated": "2024-05-01T10:00:00.120Z", "nodes": 41, "steps": 20, "steps_completed": 0, "attempts": 1,
    "step": 3, "contact_error": 1.234e-06, "iterations": 17, "progress": 10,
    "links": [
      {"href": "/v1/jobs/0f8e2a52-4d0e-4c9a-9b3e-6f2d1c0b7a11", "rel": "self", "type": "application/json", "title": "this job"},
      {"href": "/v1/jobs/0f8e2a52-4d0e-4c9a-9b3e-6f2d1c0b7a11/events", "rel": "monitor", "type": "text/event-stream",
       "title": "events: replayed, then live"},
      {"href": "/v1/jobs/0f8e2a52-4d0e-4c9a-9b3e-6f2d1c0b7a11/convergence", "rel": "related", "type": "application/json",
       "title": "contact error history"}
    ]
  })");
  expect_valid(running, SchemaName::job);

  json accepted = running;
  for (const char* k : {"started", "step", "contact_error", "iterations"}) accepted.erase(k);
  accepted["status"] = "accepted";
  accepted["message"] = "";
  accepted["progress"] = 0;
  expect_valid(accepted, SchemaName::job);

  json done = running;
  for (const char* k : {"step", "contact_error"}) done.erase(k);
  done["status"] = "successful";
  done["message"] = "solved 20 steps";
  done["finished"] = "2024-05-01T10:00:02.500Z";
  done["solve_seconds"] = 2.3;
  done["progress"] = 100;
  done["links"].push_back({{"href", "/v1/jobs/0f8e2a52-4d0e-4c9a-9b3e-6f2d1c0b7a11/result"},
                           {"rel", "http://www.opengis.net/def/rel/ogc/1.0/results"},
                           {"type", "application/json"},
                           {"title", "result"}});
  expect_valid(done, SchemaName::job);

  json removed = done;
  removed["status"] = "dismissed";
  removed["message"] = "removed with its events and result";
  removed["links"] = json::array();
  expect_valid(removed, SchemaName::job);
}

}  // namespace
}  // namespace grip
