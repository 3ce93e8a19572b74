#include "server/meshes.hpp"

#include <openssl/evp.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "server/compression.hpp"
#include "server/util.hpp"
#include "solver/io/gmsh_mesh.hpp"

namespace grip::server {

std::string sha256_hex(std::string_view bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("sha256: libcrypto failed");
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

namespace {

// The arrays' bytes, roughly: what the cache is bounded by.
std::size_t mesh_bytes(const GmshMesh& m) {
  std::size_t n = m.nodes.size() * sizeof(Vec2) + m.node_tags.size() * sizeof(std::size_t) +
                  m.element_tags.size() * (sizeof(std::size_t) + sizeof(ElementShape) + sizeof(int)) +
                  m.element_nodes.size() * sizeof(int);
  for (const auto& [name, s] : m.surfaces) n += s.elements.size() * sizeof(int);
  for (const auto& [name, c] : m.curves) n += (c.nodes.size() + 3 * c.edges.size()) * sizeof(int);
  for (const auto& [name, p] : m.points) n += p.nodes.size() * sizeof(int);
  return n;
}

// An id as sha256_hex writes it.
bool is_mesh_id(const std::string& id) {
  return id.size() == 64 && id.find_first_not_of("0123456789abcdef") == std::string::npos;
}

}  // namespace

MeshLibrary::MeshLibrary(Store& store, std::size_t cache_bytes) : store_(store), cache_bytes_(cache_bytes) {}

MeshLibrary::Upload MeshLibrary::upload(std::string_view bytes) {
  const std::string id = sha256_hex(bytes);
  if (auto stored = store_.mesh(id)) return {*stored, nlohmann::json::parse(stored->summary), false};
  auto mesh = std::make_shared<const GmshMesh>(read_gmsh_mesh(bytes, "upload"));
  Upload up;
  up.summary = gmsh_mesh_summary(*mesh);
  up.record = {id, static_cast<std::int64_t>(bytes.size()), 0, up.summary.dump(), now_iso8601()};
  const std::string data = zstd(bytes, 3);
  up.record.stored = static_cast<std::int64_t>(data.size());
  up.created = store_.put_mesh(up.record, data);
  if (!up.created)  // stored meanwhile by another request
    if (auto stored = store_.mesh(id)) up.record = *stored;
  std::lock_guard lock(mutex_);
  keep(id, std::move(mesh));
  return up;
}

MeshRemoval MeshLibrary::remove(const std::string& id) {
  const MeshRemoval r = store_.remove_mesh(id);
  if (r == MeshRemoval::removed) {
    std::lock_guard lock(mutex_);
    const auto it = cache_.find(id);
    if (it != cache_.end() && it->second.bytes > 0) {
      cached_bytes_ -= it->second.bytes;
      cache_.erase(it);
    }
  }
  return r;
}

void MeshLibrary::keep(const std::string& id, std::shared_ptr<const GmshMesh> mesh) {
  Entry& e = cache_[id];
  cached_bytes_ -= e.bytes;
  e.bytes = mesh_bytes(*mesh) + 1;
  cached_bytes_ += e.bytes;
  std::promise<std::shared_ptr<const GmshMesh>> ready;
  ready.set_value(std::move(mesh));
  e.mesh = ready.get_future().share();
  e.used = ++clock_;
  evict();
}

void MeshLibrary::evict() {
  while (cached_bytes_ > cache_bytes_) {
    auto oldest = cache_.end();
    for (auto it = cache_.begin(); it != cache_.end(); ++it)
      if (it->second.bytes > 0 && it->second.used != clock_ &&
          (oldest == cache_.end() || it->second.used < oldest->second.used))
        oldest = it;
    if (oldest == cache_.end()) return;
    cached_bytes_ -= oldest->second.bytes;
    cache_.erase(oldest);
  }
}

std::shared_ptr<const GmshMesh> MeshLibrary::get(const std::string& id) {
  if (!is_mesh_id(id)) return nullptr;
  std::promise<std::shared_ptr<const GmshMesh>> parsing;
  Future mesh;
  {
    std::lock_guard lock(mutex_);
    const auto it = cache_.find(id);
    if (it != cache_.end()) {
      it->second.used = ++clock_;
      mesh = it->second.mesh;
    } else {
      cache_[id] = {parsing.get_future().share(), 0, ++clock_};
    }
  }
  if (mesh.valid()) return mesh.get();  // cached, or being parsed by another call
  // This call parses it; the others wait on its future.
  auto forget = [&] {
    std::lock_guard lock(mutex_);
    const auto it = cache_.find(id);
    if (it != cache_.end() && it->second.bytes == 0) cache_.erase(it);
  };
  try {
    const auto data = store_.mesh_data(id);
    if (!data) {
      forget();  // not cached: an upload may come
      parsing.set_value(nullptr);
      return nullptr;
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto parsed = std::make_shared<const GmshMesh>(read_gmsh_mesh(stored_text(*data), "mesh " + id.substr(0, 12)));
    spdlog::info("mesh {} read from the store in {:.3f} s: {} nodes, {} elements", id,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), parsed->nodes.size(),
                 parsed->element_count());
    std::lock_guard lock(mutex_);
    ++parses_;
    Entry& e = cache_[id];  // (an upload of the same bytes may have put it there meanwhile)
    cached_bytes_ -= e.bytes;
    e.bytes = mesh_bytes(*parsed) + 1;
    cached_bytes_ += e.bytes;
    e.used = ++clock_;
    parsing.set_value(parsed);
    evict();
    return parsed;
  } catch (...) {
    forget();
    parsing.set_exception(std::current_exception());
    throw;
  }
}

std::function<std::shared_ptr<const GmshMesh>(const nlohmann::json&)> MeshLibrary::resolver(MeshUse& use) {
  return [this, &use](const nlohmann::json& ref) -> std::shared_ptr<const GmshMesh> {
    if (ref.contains("file"))
      throw std::invalid_argument("the service reads uploaded meshes: POST /v1/meshes, then {\"id\": ...}");
    const std::string id = ref.at("id").get<std::string>();
    std::shared_ptr<const GmshMesh> mesh;
    try {
      mesh = get(id);
    } catch (const StoreUnavailable&) {
      use.unavailable = std::current_exception();
      throw;
    }
    if (!mesh) throw std::invalid_argument("no uploaded mesh has this id (POST /v1/meshes answers with one)");
    if (std::find(use.ids.begin(), use.ids.end(), id) == use.ids.end()) use.ids.push_back(id);
    return mesh;
  };
}

std::int64_t MeshLibrary::parses() const {
  std::lock_guard lock(mutex_);
  return parses_;
}

}  // namespace grip::server
