#pragma once
// Uploaded meshes (POST /v1/meshes, docs/design.md#the-api): a gmsh .msh file is read once at
// upload (refused with the reader's line or tag), stored zstd-compressed under the SHA-256 of
// its bytes (the same bytes are stored once), and named by scenes as body.mesh.gmsh {"id": ...}.
// Parsed meshes are kept in a small cache (least recently used out) shared by submissions and
// workers, so that a sweep of 100 jobs on one mesh parses it once per process; concurrent
// requests for a mesh being parsed wait for that one parse.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "server/store.hpp"

// Declared only: this header reaches http_front.cpp after httplib.h, which must come after
// Eigen's headers (solver/io/gmsh_mesh.hpp brings them).
namespace grip {
struct GmshMesh;
}

namespace grip::server {

// Hex SHA-256 (OpenSSL's libcrypto).
std::string sha256_hex(std::string_view bytes);

// What a scene's reading used of the uploads: the ids it named (JobRecord::meshes), and
// whether the store could not be reached (read_scene turns the resolver's exceptions into
// scene errors: the caller answers 503 instead).
struct MeshUse {
  std::vector<std::string> ids;
  std::exception_ptr unavailable;
};

class MeshLibrary {
 public:
  // `cache_bytes`: parsed meshes kept, by their arrays' size (the last one used always stays).
  explicit MeshLibrary(Store& store, std::size_t cache_bytes = std::size_t{512} << 20);

  struct Upload {
    MeshRecord record;
    nlohmann::json summary;  // gmsh_mesh_summary
    bool created = false;    // false: these bytes were stored already
  };
  // Reads and stores a .msh file. Throws GmshError (the reader's refusal), StoreUnavailable.
  Upload upload(std::string_view bytes);
  std::optional<MeshRecord> find(const std::string& id) { return store_.mesh(id); }
  MeshRemoval remove(const std::string& id);

  // The parsed upload `id`; null when no mesh has that id.
  std::shared_ptr<const GmshMesh> get(const std::string& id);
  // read_scene's MeshResolver (solver/io/scene.hpp, spelled out here: see above): {"id"}
  // references load uploads (recorded in `use`); {"file"} ones are refused.
  std::function<std::shared_ptr<const GmshMesh>(const nlohmann::json&)> resolver(MeshUse& use);

  std::int64_t parses() const;  // meshes parsed from the store by this process (tests)

 private:
  using Future = std::shared_future<std::shared_ptr<const GmshMesh>>;
  struct Entry {
    Future mesh;
    std::size_t bytes = 0;  // 0 while parsing
    std::uint64_t used = 0;
  };
  void keep(const std::string& id, std::shared_ptr<const GmshMesh> mesh);  // mutex_ held
  void evict();                                                            // mutex_ held

  Store& store_;
  const std::size_t cache_bytes_;
  mutable std::mutex mutex_;
  std::unordered_map<std::string, Entry> cache_;
  std::uint64_t clock_ = 0;
  std::size_t cached_bytes_ = 0;
  std::int64_t parses_ = 0;
};

}  // namespace grip::server
