#include "solver/io/gmsh_mesh.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <unordered_map>
#include <utility>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace grip {

namespace {

// What grip does with each gmsh element type it reads.
struct TypeInfo {
  int dimension = -1;  // -1: not read
  int nodes = 0;
  ElementShape kind = ElementShape::t3;  // for dimension 2
  int corners = 0;
};

TypeInfo type_info(std::int64_t type) {
  switch (type) {
    case 15:
      return {0, 1};
    case 1:
      return {1, 2};
    case 8:
      return {1, 3};
    case 2:
      return {2, 3, ElementShape::t3, 3};
    case 9:
      return {2, 6, ElementShape::t6, 3};
    case 3:
      return {2, 4, ElementShape::q4, 4};
    case 16:
      return {2, 8, ElementShape::q8, 4};
    case 10:
      return {2, 9, ElementShape::q9, 4};
    default:
      return {};
  }
}

// Why a type is not read, in words.
std::string refused_type(std::int64_t type) {
  static const std::map<std::int64_t, const char*> solids = {
      {4, "4-node tetrahedron"},   {5, "8-node hexahedron"},    {6, "6-node prism"},
      {7, "5-node pyramid"},       {11, "10-node tetrahedron"}, {12, "27-node hexahedron"},
      {13, "18-node prism"},       {14, "14-node pyramid"},     {17, "20-node hexahedron"},
      {18, "15-node prism"},       {19, "13-node pyramid"},     {29, "20-node tetrahedron"},
      {30, "35-node tetrahedron"}, {31, "56-node tetrahedron"}, {92, "64-node hexahedron"},
      {93, "125-node hexahedron"}};
  static const std::map<std::int64_t, const char*> other_orders = {
      {20, "9-node triangle"},       {21, "10-node triangle"},      {22, "12-node triangle"},
      {23, "15-node triangle"},      {24, "15-node triangle"},      {25, "21-node triangle"},
      {26, "4-node line"},           {27, "5-node line"},           {28, "6-node line"},
      {36, "16-node quadrilateral"}, {37, "25-node quadrilateral"}, {38, "36-node quadrilateral"},
      {39, "12-node quadrilateral"}, {40, "16-node quadrilateral"}, {41, "20-node quadrilateral"}};
  const std::string read = "grip reads t3, t6, q4, q8, q9 (gmsh types 2, 9, 3, 16, 10) and lines and points for groups";
  if (auto s = solids.find(type); s != solids.end())
    return std::string("is a 3D element (") + s->second + ", gmsh type " + std::to_string(type) +
           "): grip's bodies are plane; " + read;
  if (auto o = other_orders.find(type); o != other_orders.end())
    return std::string("is a ") + o->second + " (gmsh type " + std::to_string(type) +
           "), an order grip does not read; " + read;
  return "has gmsh type " + std::to_string(type) + ", which grip does not read; " + read;
}

bool is_space(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\f' || c == '\v'; }

// A token for a message: at most 24 characters, unprintable bytes as '?'.
std::string shown(std::string_view t) {
  std::string s(t.substr(0, 24));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  return t.size() > 24 ? s + "..." : s;
}

// The file's bytes and a read position; every read checks the end, so garbage ends in a
// GmshError and never reads past the buffer.
class Cursor {
 public:
  Cursor(std::string_view data, const std::string& source) : data_(data), source_(source) {}

  std::size_t pos() const { return pos_; }
  std::size_t left() const { return data_.size() - pos_; }
  bool at_end() {
    skip_space();
    return pos_ >= data_.size();
  }

  [[noreturn]] void fail_line(std::size_t at, const std::string& what) const {
    const auto line = 1 + std::count(data_.begin(), data_.begin() + std::min(at, data_.size()), '\n');
    throw GmshError(source_ + ":" + std::to_string(line) + ": " + what);
  }
  [[noreturn]] void fail_byte(std::size_t at, const std::string& what) const {
    throw GmshError(source_ + ": byte " + std::to_string(at) + ": " + what);
  }
  [[noreturn]] void fail(const std::string& what) const { throw GmshError(source_ + ": " + what); }

  void skip_space() {
    while (pos_ < data_.size() && is_space(data_[pos_])) ++pos_;
  }
  std::string_view token(const char* what) {
    skip_space();
    if (pos_ >= data_.size()) fail_line(pos_, std::string("the file ends (truncated?) where ") + what + " should be");
    start_ = pos_;
    while (pos_ < data_.size() && !is_space(data_[pos_])) ++pos_;
    return data_.substr(start_, pos_ - start_);
  }
  // Where the last token began (for messages).
  std::size_t token_start() const { return start_; }

  template <class T>
  T integer(const char* what) {
    const auto t = token(what);
    T value{};
    const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (error != std::errc() || end != t.data() + t.size())
      fail_line(start_, std::string("expected ") + what + ", read '" + shown(t) + "'");
    return value;
  }
  std::size_t count(const char* what) { return integer<std::size_t>(what); }
  double real(const char* what) {
    auto t = token(what);
    if (!t.empty() && t[0] == '+') t.remove_prefix(1);
    double value = 0.0;
    const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (error != std::errc() || end != t.data() + t.size())
      fail_line(start_, std::string("expected ") + what + ", read '" + shown(t) + "'");
    return value;
  }
  void expect(std::string_view word) {
    const auto t = token(std::string(word).c_str());
    if (t != word) fail_line(start_, "expected " + std::string(word) + ", read '" + shown(t) + "'");
  }
  // The rest of a line that ends ASCII text before binary data: blanks, then one '\n'.
  void end_line() {
    while (pos_ < data_.size() && (data_[pos_] == ' ' || data_[pos_] == '\t' || data_[pos_] == '\r')) ++pos_;
    if (pos_ >= data_.size() || data_[pos_] != '\n')
      fail_line(pos_, pos_ >= data_.size() ? "the file ends (truncated?) before its binary data"
                                           : "expected the end of the line before binary data");
    ++pos_;
  }
  // A quoted name (of $PhysicalNames), on one line.
  std::string quoted(const char* what) {
    skip_space();
    if (pos_ >= data_.size() || data_[pos_] != '"') fail_line(pos_, std::string("expected ") + what + " in quotes");
    const auto close = data_.find_first_of("\"\n", pos_ + 1);
    if (close == std::string_view::npos || data_[close] != '"')
      fail_line(pos_, std::string(what) + " has no closing quote");
    std::string name(data_.substr(pos_ + 1, close - pos_ - 1));
    pos_ = close + 1;
    return name;
  }

  template <class T>
  T bin(const char* what) {
    T value;
    bytes(&value, sizeof value, what);
    return value;
  }
  void bytes(void* to, std::size_t n, const char* what) {
    if (left() < n) fail_byte(pos_, std::string("the file ends (truncated?) inside ") + what);
    std::memcpy(to, data_.data() + pos_, n);
    pos_ += n;
  }
  // Fails unless `n` records of `size` bytes can follow (guards allocations and loops against
  // counts a damaged file makes up).
  void need(std::size_t n, std::size_t size, const char* what) const {
    if (size > 0 && n > left() / size)
      fail_byte(pos_, std::to_string(n) + " " + what + " cannot fit in the rest of the file (truncated?)");
  }
  // Skips a section we do not read, up to and including its end marker.
  void skip_section(std::string_view name) {
    const std::string end = "$End" + std::string(name);
    const auto at = data_.find(end, pos_);
    if (at == std::string_view::npos)
      fail_line(start_, "section $" + std::string(name) + " has no " + end + " (truncated?)");
    pos_ = at + end.size();
  }

 private:
  std::string_view data_;
  const std::string& source_;
  std::size_t pos_ = 0;
  std::size_t start_ = 0;
};

// gmsh node tag -> position in $Nodes: a table when tags are dense (as gmsh writes them),
// else a hash map.
class TagIndex {
 public:
  // Indexes the tags; {true, tag} for a tag that appears twice.
  std::pair<bool, std::size_t> build(const std::vector<std::size_t>& tags) {
    std::size_t max = 0;
    for (auto t : tags) max = std::max(max, t);
    dense_ = max <= 2 * tags.size() + 1024;
    if (dense_) {
      table_.assign(max + 1, -1);
      for (std::size_t i = 0; i < tags.size(); ++i) {
        if (table_[tags[i]] >= 0) return {true, tags[i]};
        table_[tags[i]] = static_cast<int>(i);
      }
    } else {
      map_.reserve(tags.size());
      for (std::size_t i = 0; i < tags.size(); ++i)
        if (!map_.emplace(tags[i], static_cast<int>(i)).second) return {true, tags[i]};
    }
    return {false, 0};
  }
  int find(std::int64_t tag) const {
    if (tag < 0) return -1;
    const auto t = static_cast<std::size_t>(tag);
    if (dense_) return t < table_.size() ? table_[t] : -1;
    const auto it = map_.find(t);
    return it == map_.end() ? -1 : it->second;
  }

 private:
  bool dense_ = true;
  std::vector<int> table_;
  std::unordered_map<std::size_t, int> map_;
};

struct RawEdge {
  int n = 0;
  std::array<int, 3> node{};
};

using GroupKey = std::pair<int, int>;  // (dimension, physical tag)

// Everything read, in the file's node numbering (positions in $Nodes).
struct Reading {
  bool binary = false;
  bool v4 = false;
  bool nodes_read = false, elements_read = false, entities_read = false;
  std::map<GroupKey, std::string> names;
  std::map<GroupKey, std::vector<int>> entity_groups;  // 4.1: (dimension, entity tag) -> physical tags
  std::vector<std::size_t> tags;
  std::vector<Vec2> xy;
  std::vector<double> z;
  TagIndex index;
  GmshMesh mesh;                             // elements with file node numbers until compact() renumbers
  std::vector<std::int64_t> element_entity;  // 2.2: each 2D element's elementary tag
  std::map<int, std::vector<int>> surfaces;
  std::map<int, std::vector<RawEdge>> curves;
  std::map<int, std::vector<int>> points;
};

// A line in ASCII, a byte offset in binary data.
[[noreturn]] void fail_at(const Cursor& c, const Reading& r, std::size_t at, const std::string& what) {
  r.binary ? c.fail_byte(at, what) : c.fail_line(at, what);
}

constexpr std::size_t kMaxIndex = static_cast<std::size_t>(std::numeric_limits<int>::max() - 1);

void read_format(Cursor& c, Reading& r) {
  c.expect("$MeshFormat");
  const auto version = c.token("the format version");
  if (version == "4.1") r.v4 = true;
  else if (version != "2.2")
    c.fail_line(c.token_start(), "format version " + shown(version) +
                                     " is not read: grip reads 4.1 and 2.2 (gmsh -format msh41 or msh22)");
  const auto type = c.integer<int>("the file type (0 ASCII, 1 binary)");
  if (type != 0 && type != 1)
    c.fail_line(c.token_start(), "file type " + std::to_string(type) + " is neither 0 (ASCII) nor 1 (binary)");
  r.binary = type == 1;
  const auto size = c.integer<int>("the data size");
  if (size != 8) c.fail_line(c.token_start(), "data size " + std::to_string(size) + ": grip reads 8-byte doubles");
  if (r.binary) {
    c.end_line();
    const auto at = c.pos();
    if (c.bin<std::int32_t>("the byte-order mark") != 1)
      c.fail_byte(
          at,
          "the binary data is not little-endian (or the file is damaged): grip reads what gmsh writes on x86 and ARM");
  }
  c.expect("$EndMeshFormat");
}

void read_physical_names(Cursor& c, Reading& r) {
  const auto n = c.count("the number of physical names");
  for (std::size_t i = 0; i < n; ++i) {
    const auto dimension = c.integer<int>("a physical group's dimension");
    const auto at = c.token_start();
    if (dimension < 0 || dimension > 3)
      c.fail_line(at, "physical group dimension " + std::to_string(dimension) + " is not 0 to 3");
    const auto tag = c.integer<int>("a physical group's tag");
    if (!r.names.emplace(GroupKey{dimension, tag}, c.quoted("a physical group's name")).second)
      c.fail_line(at, "physical group " + std::to_string(tag) + " of dimension " + std::to_string(dimension) +
                          " is named twice");
  }
  c.expect("$EndPhysicalNames");
}

// 4.1 only: which physical groups each point, curve and surface belongs to.
void read_entities(Cursor& c, Reading& r) {
  if (r.binary) c.end_line();
  std::array<std::size_t, 4> counts{};
  for (auto& n : counts) n = r.binary ? c.bin<std::uint64_t>("the entity counts") : c.count("an entity count");
  for (int dimension = 0; dimension < 4; ++dimension) {
    for (std::size_t i = 0; i < counts[dimension]; ++i) {
      const auto tag = r.binary ? c.bin<std::int32_t>("an entity") : c.integer<int>("an entity tag");
      for (int k = 0; k < (dimension == 0 ? 3 : 6); ++k)
        r.binary ? c.bin<double>("an entity") : c.real("an entity's box");
      const auto groups = r.binary ? c.bin<std::uint64_t>("an entity") : c.count("an entity's number of physical tags");
      auto& list = r.entity_groups[{dimension, tag}];
      for (std::size_t k = 0; k < groups; ++k)
        list.push_back(r.binary ? c.bin<std::int32_t>("an entity") : c.integer<int>("a physical tag"));
      if (dimension == 0) continue;
      const auto bounds =
          r.binary ? c.bin<std::uint64_t>("an entity") : c.count("an entity's number of bounding entities");
      if (r.binary) {
        c.need(bounds, 4, "bounding entities");
        for (std::size_t k = 0; k < bounds; ++k) c.bin<std::int32_t>("an entity");
      } else {
        for (std::size_t k = 0; k < bounds; ++k) c.integer<int>("a bounding entity tag");
      }
    }
  }
  r.entities_read = true;
  c.expect("$EndEntities");
}

void add_node(Cursor& c, Reading& r, std::size_t tag, double x, double y, double z, std::size_t at) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
    const std::string what = "node " + std::to_string(tag) + " has a coordinate that is not a finite number";
    fail_at(c, r, at, what);
  }
  r.tags.push_back(tag);
  r.xy.emplace_back(x, y);
  r.z.push_back(z);
}

void reserve_nodes(Cursor& c, Reading& r, std::size_t n, std::size_t min_bytes) {
  const auto room = std::min(n, c.left() / min_bytes + 1);
  r.tags.reserve(room);
  r.xy.reserve(room);
  r.z.reserve(room);
}

void read_nodes(Cursor& c, Reading& r) {
  if (r.nodes_read) c.fail_line(c.token_start(), "a second $Nodes section");
  if (r.binary && r.v4) c.end_line();
  if (!r.v4) {
    const auto n = c.count("the number of nodes");
    if (r.binary) {
      c.end_line();
      c.need(n, 28, "nodes");
    }
    reserve_nodes(c, r, n, 8);
    for (std::size_t i = 0; i < n; ++i) {
      if (r.binary) {
        const auto at = c.pos();
        const auto tag = c.bin<std::int32_t>("a node");
        std::array<double, 3> x;
        c.bytes(x.data(), sizeof x, "a node");
        if (tag < 0) c.fail_byte(at, "node tag " + std::to_string(tag) + " is negative");
        add_node(c, r, static_cast<std::size_t>(tag), x[0], x[1], x[2], at);
      } else {
        const auto tag = c.count("a node tag");
        const auto at = c.token_start();
        const double x = c.real("a node's x"), y = c.real("a node's y"), z = c.real("a node's z");
        add_node(c, r, tag, x, y, z, at);
      }
    }
  } else {
    if (!r.binary) c.skip_space();
    const auto head_at = c.pos();
    std::array<std::size_t, 4> head{};  // blocks, nodes, min tag, max tag
    for (auto& h : head) h = r.binary ? c.bin<std::uint64_t>("the $Nodes counts") : c.count("a $Nodes count");
    reserve_nodes(c, r, head[1], r.binary ? 32 : 8);
    std::vector<std::size_t> block_tags;
    for (std::size_t b = 0; b < head[0]; ++b) {
      if (!r.binary) c.skip_space();
      const auto block_at = c.pos();
      int dimension, parametric;
      std::size_t n;
      if (r.binary) {
        dimension = c.bin<std::int32_t>("a node block");
        c.bin<std::int32_t>("a node block");
        parametric = c.bin<std::int32_t>("a node block");
        n = c.bin<std::uint64_t>("a node block");
      } else {
        dimension = c.integer<int>("a node block's entity dimension");
        c.integer<int>("a node block's entity tag");
        parametric = c.integer<int>("a node block's parametric flag");
        n = c.count("a node block's number of nodes");
      }
      if (dimension < 0 || dimension > 3 || (parametric != 0 && parametric != 1)) {
        const std::string what = "node block with entity dimension " + std::to_string(dimension) +
                                 " and parametric flag " + std::to_string(parametric);
        fail_at(c, r, block_at, what);
      }
      const std::size_t values = 3 + (parametric ? dimension : 0);  // x y z, then u [v [w]]
      if (r.binary) {
        c.need(n, 8 * (1 + values), "nodes");
        block_tags.resize(n);
        c.bytes(block_tags.data(), 8 * n, "a node block");
        std::array<double, 6> x{};
        for (std::size_t i = 0; i < n; ++i) {
          const auto at = c.pos();
          c.bytes(x.data(), 8 * values, "a node block");
          add_node(c, r, block_tags[i], x[0], x[1], x[2], at);
        }
      } else {
        block_tags.clear();
        for (std::size_t i = 0; i < n; ++i) block_tags.push_back(c.count("a node tag"));
        for (std::size_t i = 0; i < n; ++i) {
          const double x = c.real("a node's x");
          const auto at = c.token_start();
          const double y = c.real("a node's y"), z = c.real("a node's z");
          for (std::size_t k = 3; k < values; ++k) c.real("a node's parametric coordinate");
          add_node(c, r, block_tags[i], x, y, z, at);
        }
      }
    }
    if (r.tags.size() != head[1])
      fail_at(
          c, r, head_at,
          "$Nodes declares " + std::to_string(head[1]) + " nodes, its blocks hold " + std::to_string(r.tags.size()));
  }
  if (r.tags.size() > kMaxIndex) c.fail("more nodes than grip numbers (" + std::to_string(r.tags.size()) + ")");
  if (const auto [twice, tag] = r.index.build(r.tags); twice)
    c.fail("node tag " + std::to_string(tag) + " appears twice in $Nodes");
  r.nodes_read = true;
  c.expect("$EndNodes");
}

// One element: its type, tag, node tags (already resolved to positions in $Nodes) and the
// physical groups it carries.
void add_element(Reading& r, const TypeInfo& info, std::size_t tag, const int* nodes, std::span<const int> groups,
                 std::int64_t entity) {
  if (info.dimension == 2) {
    auto& m = r.mesh;
    // gmsh's 2.2 writer repeats an element once per physical group of its entity, under a new
    // tag: the repetition is the same element in one more group.
    const bool repeat = !r.v4 && !r.element_entity.empty() && r.element_entity.back() == entity &&
                        m.element_kinds.back() == info.kind &&
                        std::equal(nodes, nodes + info.nodes, m.element_nodes.end() - info.nodes);
    if (!repeat) {
      m.element_tags.push_back(tag);
      m.element_kinds.push_back(info.kind);
      m.element_nodes.insert(m.element_nodes.end(), nodes, nodes + info.nodes);
      m.element_offsets.push_back(static_cast<int>(m.element_nodes.size()));
      if (!r.v4) r.element_entity.push_back(entity);
    }
    const int e = m.element_count() - 1;
    for (int g : groups) r.surfaces[g].push_back(e);
  } else if (info.dimension == 1) {
    RawEdge edge{info.nodes, {nodes[0], nodes[1], info.nodes == 3 ? nodes[2] : -1}};
    for (int g : groups) r.curves[g].push_back(edge);
  } else {
    for (int g : groups) r.points[g].push_back(nodes[0]);
  }
}

// Node tags -> positions in $Nodes; fails naming the element and the missing tag.
template <class Tag>
void resolve(Cursor& c, const Reading& r, std::size_t element, const Tag* tags, int n, int* out, std::size_t at) {
  for (int k = 0; k < n; ++k) {
    out[k] = r.index.find(static_cast<std::int64_t>(tags[k]));
    if (out[k] < 0) {
      const std::string what = "element " + std::to_string(element) + " refers to node " +
                               std::to_string(static_cast<std::int64_t>(tags[k])) + ", which is not in $Nodes";
      fail_at(c, r, at, what);
    }
  }
}

TypeInfo checked_type(Cursor& c, const Reading& r, std::int64_t type, std::size_t element, std::size_t at) {
  const auto info = type_info(type);
  if (info.dimension < 0) {
    const std::string what = "element " + std::to_string(element) + " " + refused_type(type);
    fail_at(c, r, at, what);
  }
  return info;
}

void read_elements_v2(Cursor& c, Reading& r) {
  const auto n = c.count("the number of elements");
  std::array<int, 9> nodes{};
  std::vector<int> group(1);
  if (!r.binary) {
    for (std::size_t i = 0; i < n; ++i) {
      const auto tag = c.count("an element tag");
      const auto at = c.token_start();
      const auto info = checked_type(c, r, c.integer<std::int64_t>("an element type"), tag, at);
      const auto ntags = c.count("an element's number of tags");
      int physical = 0;
      std::int64_t entity = 0;
      for (std::size_t k = 0; k < ntags; ++k) {
        const auto t = c.integer<std::int64_t>("an element tag (physical, elementary, ...)");
        if (k == 0) physical = static_cast<int>(std::clamp<std::int64_t>(t, INT32_MIN, INT32_MAX));
        if (k == 1) entity = t;
      }
      std::array<std::int64_t, 9> node_tags{};
      for (int k = 0; k < info.nodes; ++k) node_tags[k] = c.integer<std::int64_t>("an element's node tag");
      resolve(c, r, tag, node_tags.data(), info.nodes, nodes.data(), at);
      group[0] = physical;
      add_element(r, info, tag, nodes.data(), std::span<const int>(group.data(), physical != 0 ? 1 : 0), entity);
    }
  } else {
    c.end_line();
    std::size_t done = 0;
    std::vector<std::int32_t> record;
    while (done < n) {
      const auto at = c.pos();
      const auto type = c.bin<std::int32_t>("an element block header");
      const auto count = c.bin<std::int32_t>("an element block header");
      const auto ntags = c.bin<std::int32_t>("an element block header");
      if (count <= 0 || ntags < 0 || static_cast<std::size_t>(count) > n - done)
        c.fail_byte(at, "element block header (type " + std::to_string(type) + ", " + std::to_string(count) +
                            " elements, " + std::to_string(ntags) + " tags) does not fit the " + std::to_string(n) +
                            " elements declared");
      c.need(1, 4 * (static_cast<std::size_t>(ntags) + 1), "element records");
      if (type_info(type).dimension < 0)
        checked_type(c, r, type, static_cast<std::size_t>(c.bin<std::int32_t>("an element")), at);
      const auto info = type_info(type);
      const std::size_t size = 1 + ntags + info.nodes;
      c.need(count, 4 * size, "elements");
      record.resize(size);
      for (std::int32_t i = 0; i < count; ++i) {
        const auto element_at = c.pos();
        c.bytes(record.data(), 4 * size, "an element");
        if (record[0] < 0) c.fail_byte(element_at, "element tag " + std::to_string(record[0]) + " is negative");
        const auto tag = static_cast<std::size_t>(record[0]);
        resolve(c, r, tag, record.data() + 1 + ntags, info.nodes, nodes.data(), element_at);
        group[0] = ntags > 0 ? record[1] : 0;
        add_element(r, info, tag, nodes.data(), std::span<const int>(group.data(), group[0] != 0 ? 1 : 0),
                    ntags > 1 ? record[2] : 0);
      }
      done += count;
    }
  }
}

void read_elements_v4(Cursor& c, Reading& r) {
  if (r.binary) c.end_line();
  if (!r.binary) c.skip_space();
  const auto head_at = c.pos();
  std::array<std::size_t, 4> head{};  // blocks, elements, min tag, max tag
  for (auto& h : head) h = r.binary ? c.bin<std::uint64_t>("the $Elements counts") : c.count("an $Elements count");
  std::array<int, 9> nodes{};
  std::array<std::uint64_t, 10> record{};
  const std::vector<int> none;
  std::size_t total = 0;
  for (std::size_t b = 0; b < head[0]; ++b) {
    if (!r.binary) c.skip_space();
    const auto block_at = c.pos();
    int dimension, entity;
    std::int64_t type;
    std::size_t n;
    if (r.binary) {
      dimension = c.bin<std::int32_t>("an element block");
      entity = c.bin<std::int32_t>("an element block");
      type = c.bin<std::int32_t>("an element block");
      n = c.bin<std::uint64_t>("an element block");
    } else {
      dimension = c.integer<int>("an element block's entity dimension");
      entity = c.integer<int>("an element block's entity tag");
      type = c.integer<std::int64_t>("an element block's element type");
      n = c.count("an element block's number of elements");
    }
    if (n == 0) continue;
    if (type_info(type).dimension < 0) {
      const auto first = r.binary ? c.bin<std::uint64_t>("an element") : c.count("an element tag");
      checked_type(c, r, type, first, r.binary ? block_at : c.token_start());
    }
    const auto info = type_info(type);
    if (info.dimension != dimension) {
      const std::string what = "element block of gmsh type " + std::to_string(type) + " (dimension " +
                               std::to_string(info.dimension) + ") on an entity of dimension " +
                               std::to_string(dimension);
      fail_at(c, r, block_at, what);
    }
    const auto found = r.entity_groups.find({dimension, entity});
    const auto& groups = found == r.entity_groups.end() ? none : found->second;
    if (r.binary) c.need(n, 8 * (1 + info.nodes), "elements");
    if (info.dimension == 2) {
      auto& m = r.mesh;
      const auto room = std::min(n, c.left() / (2 * (1 + info.nodes)) + 1);
      m.element_tags.reserve(m.element_tags.size() + room);
      m.element_kinds.reserve(m.element_kinds.size() + room);
      m.element_offsets.reserve(m.element_offsets.size() + room);
      m.element_nodes.reserve(m.element_nodes.size() + room * info.nodes);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!r.binary) c.skip_space();
      const auto at = c.pos();
      if (r.binary) {
        c.bytes(record.data(), 8 * (1 + info.nodes), "an element");
      } else {
        for (int k = 0; k <= info.nodes; ++k) record[k] = c.count(k == 0 ? "an element tag" : "an element's node tag");
      }
      const auto tag = static_cast<std::size_t>(record[0]);
      resolve(c, r, tag, record.data() + 1, info.nodes, nodes.data(), at);
      add_element(r, info, tag, nodes.data(), groups, entity);
    }
    total += n;
  }
  if (total != head[1])
    fail_at(c, r, head_at,
            "$Elements declares " + std::to_string(head[1]) + " elements, its blocks hold " + std::to_string(total));
}

void read_elements(Cursor& c, Reading& r) {
  if (r.elements_read) c.fail_line(c.token_start(), "a second $Elements section");
  if (!r.nodes_read) c.fail_line(c.token_start(), "$Elements comes before $Nodes");
  r.v4 ? read_elements_v4(c, r) : read_elements_v2(c, r);
  if (r.mesh.element_nodes.size() > kMaxIndex) c.fail("more element nodes than grip numbers");
  r.elements_read = true;
  c.expect("$EndElements");
}

// Twice the signed area of the corners (counter-clockwise positive), and the longest corner
// distance squared: zero area is judged relative to the element's size.
std::pair<double, double> corner_area(const std::vector<Vec2>& xy, std::span<const int> nodes, int corners) {
  double area = 0.0, longest = 0.0;
  for (int k = 0; k < corners; ++k) {
    const Vec2& a = xy[nodes[k]];
    const Vec2& b = xy[nodes[(k + 1) % corners]];
    area += a.x() * b.y() - a.y() * b.x();
    longest = std::max(longest, (b - a).squaredNorm());
  }
  return {area, longest};
}

// The same element counter-clockwise: corners reversed from corner 0, mid-sides after them.
void reorient(ElementShape kind, std::span<int> n) {
  static constexpr std::array<int, 9> t6 = {0, 2, 1, 5, 4, 3};
  static constexpr std::array<int, 9> q9 = {0, 3, 2, 1, 7, 6, 5, 4, 8};
  const auto& order = element_corner_count(kind) == 3 ? t6 : q9;
  std::array<int, 9> copy{};
  std::copy(n.begin(), n.end(), copy.begin());
  for (std::size_t k = 0; k < n.size(); ++k) n[k] = copy[order[k]];
}

void check_elements(const Cursor& c, Reading& r) {
  auto& m = r.mesh;
  for (int e = 0; e < m.element_count(); ++e) {
    const int begin = m.element_offsets[e], end = m.element_offsets[e + 1];
    std::span<int> nodes(m.element_nodes.data() + begin, m.element_nodes.data() + end);
    for (std::size_t a = 0; a < nodes.size(); ++a)
      for (std::size_t b = a + 1; b < nodes.size(); ++b)
        if (nodes[a] == nodes[b])
          c.fail("element " + std::to_string(m.element_tags[e]) + " uses node " + std::to_string(r.tags[nodes[a]]) +
                 " twice");
    const auto kind = m.element_kinds[e];
    const int corners = element_corner_count(kind);
    const auto [area, longest] = corner_area(r.xy, nodes, corners);
    if (!(std::abs(area) > 1e-12 * longest))
      c.fail("element " + std::to_string(m.element_tags[e]) + " has zero area (its corners lie on one line)");
    if (area < 0) {
      reorient(kind, nodes);
      ++m.reoriented;
    }
  }
}

// Nodes of 2D elements first, then those only groups use; all in $Nodes order. Renumbers the
// elements and groups and checks that the kept nodes lie in one plane z = const.
std::vector<int> compact(const Cursor& c, Reading& r) {
  auto& m = r.mesh;
  std::vector<char> use(r.tags.size(), 0);  // 2: a 2D element's, 1: a group's
  for (int n : m.element_nodes) use[n] = 2;
  auto mark = [&](int n) { use[n] = std::max<char>(use[n], 1); };
  for (auto& [tag, edges] : r.curves)
    for (auto& e : edges)
      for (int k = 0; k < e.n; ++k) mark(e.node[k]);
  for (auto& [tag, nodes] : r.points)
    for (int n : nodes) mark(n);
  std::vector<int> number(r.tags.size(), -1);
  const auto kept = r.tags.size() - std::count(use.begin(), use.end(), 0);
  m.nodes.reserve(kept);
  m.node_tags.reserve(kept);
  int next = 0;
  for (char level : {2, 1})
    for (std::size_t i = 0; i < use.size(); ++i)
      if (use[i] == level) {
        number[i] = next++;
        m.nodes.push_back(r.xy[i]);
        m.node_tags.push_back(r.tags[i]);
      }
  m.body_nodes = static_cast<int>(std::count(use.begin(), use.end(), 2));

  // In one plane: z within a hair of the first kept node's, relative to the mesh's size.
  double extent = 0.0, z0 = 0.0;
  bool first = true;
  Vec2 low = Vec2::Constant(0.0), high = low;
  for (std::size_t i = 0; i < use.size(); ++i) {
    if (!use[i]) continue;
    if (first) {
      low = high = r.xy[i];
      z0 = r.z[i];
      first = false;
    }
    low = low.cwiseMin(r.xy[i]);
    high = high.cwiseMax(r.xy[i]);
  }
  extent = (high - low).maxCoeff();
  for (std::size_t i = 0; i < use.size(); ++i)
    if (use[i] && !(std::abs(r.z[i] - z0) <= 1e-9 * std::max(extent, std::abs(z0))))
      c.fail("node " + std::to_string(r.tags[i]) + " has z = " + std::to_string(r.z[i]) +
             " where others have z = " + std::to_string(z0) + ": grip reads plane meshes, in one plane z = const");

  for (int& n : m.element_nodes) n = number[n];
  return number;
}

// A curve's nodes in order along it when its edges make one chain.
void order_curve(GmshCurve& curve) {
  const auto& edges = curve.edges;
  std::unordered_map<int, std::vector<int>> touching;  // end node -> edges
  bool simple = !edges.empty();
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (edges[e][0] == edges[e][1]) simple = false;
    touching[edges[e][0]].push_back(static_cast<int>(e));
    touching[edges[e][1]].push_back(static_cast<int>(e));
  }
  int start = -1, ends = 0;
  for (auto& [node, list] : touching) {
    if (list.size() > 2) simple = false;
    if (list.size() == 1) ++ends, start = start < 0 ? node : std::min(start, node);
  }
  simple = simple && (ends == 2 || ends == 0);
  std::vector<int> order;
  if (simple) {
    const bool closed = ends == 0;
    int at = closed ? edges[0][0] : start;
    std::vector<char> used(edges.size(), 0);
    int forward = 0;
    order.push_back(at);
    for (std::size_t step = 0; step < edges.size(); ++step) {
      int next_edge = -1;
      if (step == 0 && closed) next_edge = 0;
      else
        for (int e : touching[at])
          if (!used[e]) next_edge = e;
      if (next_edge < 0) break;
      used[next_edge] = 1;
      const auto& edge = edges[next_edge];
      const bool along = edge[0] == at;
      forward += along ? 1 : -1;
      if (edge.size() == 3) order.push_back(edge[2]);
      at = along ? edge[1] : edge[0];
      if (!(closed && step + 1 == edges.size())) order.push_back(at);
    }
    if (std::count(used.begin(), used.end(), 1) == static_cast<long>(edges.size())) {
      if (!closed && forward < 0) std::reverse(order.begin(), order.end());
      curve.nodes = std::move(order);
      curve.chain = true;
      curve.closed = closed;
      return;
    }
  }
  std::vector<char> seen;
  for (const auto& edge : edges)
    for (int k : {0, 2, 1})
      if (k < static_cast<int>(edge.size())) {
        const int n = edge[k];
        if (static_cast<std::size_t>(n) >= seen.size()) seen.resize(n + 1, 0);
        if (!seen[n]) seen[n] = 1, curve.nodes.push_back(n);
      }
}

void make_groups(const Cursor& c, Reading& r, const std::vector<int>& number) {
  auto& m = r.mesh;
  auto name_of = [&](int dimension, int tag) {
    const auto it = r.names.find({dimension, tag});
    if (it != r.names.end()) return it->second;
    return std::string(dimension == 2 ? "surface_" : dimension == 1 ? "curve_" : "point_") + std::to_string(tag);
  };
  std::map<std::string, std::pair<int, int>> taken;  // node set names: curves and points
  auto claim = [&](int dimension, int tag, const std::string& name, bool node_set) {
    if (!node_set) return;
    const auto [it, fresh] = taken.emplace(name, std::pair{dimension, tag});
    if (!fresh)
      c.fail("physical groups " + std::to_string(it->second.second) + " (dimension " +
             std::to_string(it->second.first) + ") and " + std::to_string(tag) + " (dimension " +
             std::to_string(dimension) + ") are both named '" + name + "'");
  };
  // Named groups that hold no element stay, empty: a scene naming them learns they are empty.
  for (const auto& [key, name] : r.names) {
    if (key.first == 2) r.surfaces[key.second];
    if (key.first == 1) r.curves[key.second];
    if (key.first == 0) r.points[key.second];
  }
  for (auto& [tag, elements] : r.surfaces) {
    const auto name = name_of(2, tag);
    std::sort(elements.begin(), elements.end());
    elements.erase(std::unique(elements.begin(), elements.end()), elements.end());
    if (!m.surfaces.emplace(name, GmshSurface{tag, std::move(elements)}).second)
      c.fail("two physical surfaces are named '" + name + "'");
  }
  for (auto& [tag, edges] : r.curves) {
    const auto name = name_of(1, tag);
    claim(1, tag, name, true);
    GmshCurve curve{tag, {}, {}, false, false};
    for (const auto& e : edges) {
      std::vector<int> nodes;
      for (int k = 0; k < e.n; ++k) nodes.push_back(number[e.node[k]]);
      curve.edges.push_back(std::move(nodes));
    }
    order_curve(curve);
    m.curves.emplace(name, std::move(curve));
  }
  std::vector<int> in_group(m.nodes.size(), 0);  // the last point group that listed each node
  int group = 0;
  for (auto& [tag, nodes] : r.points) {
    const auto name = name_of(0, tag);
    claim(0, tag, name, true);
    GmshPoints set{tag, {}};
    ++group;
    for (int n : nodes)
      if (std::exchange(in_group[number[n]], group) != group) set.nodes.push_back(number[n]);
    m.points.emplace(name, std::move(set));
  }
}

}  // namespace

GmshMesh read_gmsh_mesh(std::string_view bytes, const std::string& source) {
  Cursor c(bytes, source);
  Reading r;
  if (c.at_end()) c.fail("the file is empty");
  read_format(c, r);
  while (!c.at_end()) {
    const auto section = c.token("a section");
    if (section.empty() || section[0] != '$')
      c.fail_line(c.token_start(), "expected a section ($Name), read '" + shown(section) + "'");
    const auto name = section.substr(1);
    if (name == "PhysicalNames") read_physical_names(c, r);
    else if (name == "Entities") {
      if (!r.v4) c.skip_section(name);  // 2.2 has no $Entities; groups come with each element
      else if (r.nodes_read || r.entities_read) c.fail_line(c.token_start(), "$Entities after $Nodes, or twice");
      else read_entities(c, r);
    } else if (name == "Nodes") read_nodes(c, r);
    else if (name == "Elements") read_elements(c, r);
    else if (name == "PartitionedEntities")
      c.fail_line(c.token_start(), "a partitioned mesh: grip reads whole meshes (save without partitions)");
    else if (name.starts_with("End")) c.fail_line(c.token_start(), "'" + shown(section) + "' closes no open section");
    else c.skip_section(name);
  }
  if (!r.nodes_read) c.fail("no $Nodes section (truncated?)");
  if (!r.elements_read) c.fail("no $Elements section (truncated?)");
  check_elements(c, r);
  const auto number = compact(c, r);
  make_groups(c, r, number);
  return std::move(r.mesh);
}

GmshMesh read_gmsh_file(const std::string& path) {
  // Mapped, not copied: no second copy of a large file, and its pages come in one go.
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) throw GmshError(path + ": cannot open: " + std::strerror(errno));
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd);
    throw GmshError(path + ": not a readable file");
  }
  const auto size = static_cast<std::size_t>(info.st_size);
  if (size == 0) {
    ::close(fd);
    return read_gmsh_mesh({}, path);
  }
  void* data = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
  ::close(fd);
  if (data == MAP_FAILED) throw GmshError(path + ": cannot read: " + std::strerror(errno));
  struct Unmap {
    void* data;
    std::size_t size;
    ~Unmap() { ::munmap(data, size); }
  } unmap{data, size};
  return read_gmsh_mesh(std::string_view(static_cast<const char*>(data), size), path);
}

nlohmann::json gmsh_mesh_summary(const GmshMesh& mesh) {
  std::array<int, 5> per_kind{};
  for (auto kind : mesh.element_kinds) ++per_kind[static_cast<int>(kind)];
  nlohmann::json elements = nlohmann::json::object();
  for (int k = 0; k < 5; ++k)
    if (per_kind[k] > 0) elements[shape_name(static_cast<ElementShape>(k))] = per_kind[k];
  nlohmann::json groups = nlohmann::json::array();
  std::vector<int> in_group(mesh.nodes.size(), -1);  // the last surface that counted each node
  int group = 0;
  for (const auto& [name, s] : mesh.surfaces) {
    int nodes = 0;
    for (int e : s.elements)
      for (int n : mesh.element(e)) nodes += std::exchange(in_group[n], group) != group;
    ++group;
    groups.push_back(
        {{"name", name}, {"dimension", 2}, {"tag", s.tag}, {"elements", s.elements.size()}, {"nodes", nodes}});
  }
  for (const auto& [name, curve] : mesh.curves)
    groups.push_back({{"name", name},
                      {"dimension", 1},
                      {"tag", curve.tag},
                      {"edges", curve.edges.size()},
                      {"nodes", curve.nodes.size()}});
  for (const auto& [name, p] : mesh.points)
    groups.push_back({{"name", name}, {"dimension", 0}, {"tag", p.tag}, {"nodes", p.nodes.size()}});
  nlohmann::json box = nullptr;
  const std::size_t boxed = mesh.body_nodes > 0 ? mesh.body_nodes : mesh.nodes.size();
  if (boxed > 0) {
    Vec2 low = mesh.nodes[0], high = mesh.nodes[0];
    for (std::size_t i = 0; i < boxed; ++i) low = low.cwiseMin(mesh.nodes[i]), high = high.cwiseMax(mesh.nodes[i]);
    box = {{"min", {low.x(), low.y()}}, {"max", {high.x(), high.y()}}};
  }
  return {{"nodes", mesh.nodes.size()},    {"body_nodes", mesh.body_nodes}, {"elements", elements},
          {"reoriented", mesh.reoriented}, {"physical_groups", groups},     {"bounding_box", box}};
}

}  // namespace grip
