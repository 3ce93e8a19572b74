#include "solver/io/schema_validation.hpp"

#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/constraint_builder.hpp>
#include <valijson/constraints/concrete_constraints.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validation_results.hpp>
#include <valijson/validator.hpp>

#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <regex>
#include <set>
#include <stdexcept>
#include <string>

#include "solver/io/embedded_schemas.hpp"
#include "solver/io/scene_reader.hpp"

namespace grip {
namespace {

using nlohmann::json;
using scene_io::show;
using Tokens = std::vector<std::string>;

// ---- loading

// Collecting stops once this many errors are collected (wrappers and repeats included): a
// document's errors then cost at most about that many, however large it is (80,000 invalid
// entries made valijson collect every error of every entry before any was described).
constexpr size_t kEnough = 10 * kMaxSceneIssues;
constexpr const char* kEnoughKeyword = "x-grip-enough";

// Thrown by the kEnoughKeyword constraint out of valijson's visitor: it ends the collection,
// carrying the errors of the results it was collecting into (under an if/then or an anyOf
// those are a nested visitor's, which the unwinding drops).
struct Enough {
  std::vector<valijson::ValidationResults::Error> errors;
};

// kEnoughKeyword: a constraint that every value passes; while errors are collected it ends
// the collection at kEnough of them.
class EnoughConstraint : public valijson::constraints::PolyConstraint {
 public:
  bool validate(const valijson::adapters::Adapter&, const std::vector<std::string>&,
                valijson::ValidationResults* results) const override {
    if (results && results->numErrors() >= kEnough) {
      Enough enough;
      valijson::ValidationResults::Error e;
      while (results->popError(e)) enough.errors.push_back(std::move(e));
      throw enough;
    }
    return true;
  }

 private:
  Constraint* cloneInto(void* where) const override { return new (where) EnoughConstraint(*this); }
  size_t sizeOf() const override { return sizeof(EnoughConstraint); }
};

class EnoughBuilder : public valijson::ConstraintBuilder {
 public:
  valijson::constraints::Constraint* make(const valijson::adapters::Adapter&) const override {
    return new EnoughConstraint;
  }
};

// Two rewrites that keep each schema's meaning and sharpen valijson's reports:
// - a `false` subschema (`additionalProperties: false`) becomes {"not": {}}: valijson reports
//   a false subschema only through wrapper errors and names only the first unknown key, but
//   a failing `not` is reported for every key at its own pointer;
// - a `oneOf` whose branches are told apart by a `const` property (an event's "type") becomes
//   an enum of that property plus one if/then per branch, so that only the branch the
//   document chose reports its errors (valijson reports every branch's errors otherwise).
class Rewriter {
 public:
  explicit Rewriter(const json& root) : root_(root) {}

  // In place on a subschema it owns (moved in and out: copying each subtree at each level took
  // 9.5 M of the 17 M instructions of the scene validator's build).
  json schema(json s) const {
    if (s.is_boolean()) return s.get<bool>() ? json::object() : json{{"not", json::object()}};
    if (!s.is_object()) return s;
    // Each subschema with keywords of its own checks the collected errors' count (kEnough).
    if (!s.empty() && !s.contains("$ref")) s[kEnoughKeyword] = true;
    for (const char* key :
         {"additionalProperties", "additionalItems", "contains", "propertyNames", "not", "if", "then", "else"})
      if (s.contains(key)) s[key] = schema(std::move(s[key]));
    for (const char* key : {"properties", "patternProperties", "definitions"})
      if (s.contains(key) && s[key].is_object())
        for (json& sub : s[key]) sub = schema(std::move(sub));
    if (s.contains("dependencies") && s["dependencies"].is_object())
      for (json& sub : s["dependencies"])
        if (!sub.is_array()) sub = schema(std::move(sub));
    if (s.contains("items"))
      s["items"] = s["items"].is_array() ? list(std::move(s["items"])) : schema(std::move(s["items"]));
    for (const char* key : {"allOf", "anyOf", "oneOf"})
      if (s.contains(key) && s[key].is_array()) s[key] = list(std::move(s[key]));
    if (s.contains("oneOf")) split_discriminated(s);
    return s;
  }

 private:
  json list(json a) const {
    for (json& sub : a) sub = schema(std::move(sub));
    return a;
  }

  const json& local(const json& s) const {
    if (s.is_object() && s.contains("$ref") && s["$ref"].is_string()) {
      const std::string ref = s["$ref"];
      if (ref.rfind("#", 0) == 0) return root_.at(json::json_pointer(ref.substr(1)));
    }
    return s;
  }

  void split_discriminated(json& s) const {
    const json& branches = s["oneOf"];
    if (branches.size() < 2) return;
    std::optional<std::string> key;
    const json first = local(branches[0]).value("properties", json::object());
    for (const auto& [name, sub] : first.items())
      if (sub.is_object() && sub.contains("const")) {
        bool everywhere = true;
        for (const auto& b : branches) {
          const json& r = local(b);
          everywhere &= r.is_object() && r.contains("properties") && r["properties"].contains(name) &&
                        r["properties"][name].is_object() && r["properties"][name].contains("const") &&
                        r.contains("required") && std::count(r["required"].begin(), r["required"].end(), name) > 0;
        }
        if (everywhere) {
          key = name;
          break;
        }
      }
    if (!key) return;
    json values = json::array();
    for (const auto& b : branches) {
      const json& v = local(b)["properties"][*key]["const"];
      if (std::find(values.begin(), values.end(), v) != values.end()) return;  // not distinct
      values.push_back(v);
    }
    json all = s.value("allOf", json::array());
    all.push_back({{"required", {*key}}, {"properties", {{*key, {{"enum", values}}}}}});
    for (size_t i = 0; i < branches.size(); ++i)
      all.push_back(
          {{"if", {{"required", {*key}}, {"properties", {{*key, {{"const", values[i]}}}}}}}, {"then", branches[i]}});
    s.erase("oneOf");
    s["allOf"] = all;
  }

  const json& root_;
};

struct Registry;

// One embedded schema: parsed and rewritten on first use, made a valijson schema on the first
// validation against it (grip solve validates a scene only; building all four took 3 % of a
// refined Hertz run).
class Loaded {
 public:
  explicit Loaded(std::string_view text) : text(text) {}
  const std::string_view text;

  const json& doc() const {
    std::call_once(doc_once_, [this] {
      const json original = json::parse(text);
      doc_ = Rewriter(original).schema(original);  // a copy of the original, rewritten in place
    });
    return doc_;
  }
  const valijson::Schema& schema(const Registry& reg, std::string_view stem) const;

 private:
  mutable std::once_flag doc_once_, schema_once_;
  mutable json doc_;
  mutable std::unique_ptr<valijson::Schema> schema_;
};

struct Registry {
  std::map<std::string, Loaded, std::less<>> by_stem;

  const Loaded& get(std::string_view stem) const {
    const auto it = by_stem.find(stem);
    if (it == by_stem.end())
      throw std::logic_error("no schema schemas/" + std::string(stem) + ".schema.json was embedded");
    return it->second;
  }
};

// "scene.schema.json", "./scene.schema.json#/definitions/x", ".../v1/schemas/scene" -> "scene".
std::string stem_of(const std::string& uri) {
  std::string name = uri.substr(0, uri.find('#'));
  name = name.substr(name.find_last_of('/') + 1);
  const std::string suffix = ".schema.json";
  if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
    name.resize(name.size() - suffix.size());
  return name;
}

const valijson::Schema& Loaded::schema(const Registry& reg, std::string_view stem) const {
  std::call_once(schema_once_, [&] {
    // References to sibling schemas ("$ref": "scene.schema.json") resolve to embedded ones.
    auto fetch = [&reg](const std::string& uri) -> const json* {
      const auto it = reg.by_stem.find(stem_of(uri));
      return it == reg.by_stem.end() ? nullptr : new json(it->second.doc());
    };
    auto release = [](const json* doc) { delete doc; };
    auto schema = std::make_unique<valijson::Schema>();
    valijson::SchemaParser parser;
    parser.addConstraintBuilder(kEnoughKeyword, new EnoughBuilder);  // the parser deletes it
    const valijson::adapters::NlohmannJsonAdapter adapter(doc());
    try {
      parser.populateSchema(adapter, *schema, fetch, release);
    } catch (const std::exception& ex) {
      throw std::logic_error("schemas/" + std::string(stem) + ".schema.json is not a usable schema: " + ex.what());
    }
    schema_ = std::move(schema);
  });
  return *schema_;
}

Registry load() {
  Registry reg;
  for (size_t i = 0; i < schema_io::kEmbeddedSchemaCount; ++i) {
    const auto& e = schema_io::kEmbeddedSchemas[i];
    reg.by_stem.emplace(std::piecewise_construct, std::forward_as_tuple(e.stem), std::forward_as_tuple(e.text));
  }
  return reg;
}

const Registry& registry() {
  static const Registry reg = load();
  return reg;
}

// ---- which subschemas apply where

bool type_matches(const json& value, const std::string& type) {
  if (type == "integer") return value.is_number_integer();
  if (type == "number") return value.is_number();
  if (type == "string") return value.is_string();
  if (type == "object") return value.is_object();
  if (type == "array") return value.is_array();
  if (type == "boolean") return value.is_boolean();
  if (type == "null") return value.is_null();
  return true;
}

bool types_match(const json& value, const json& type) {
  if (type.is_string()) return type_matches(value, type.get<std::string>());
  for (const auto& t : type)
    if (t.is_string() && type_matches(value, t.get<std::string>())) return true;
  return false;
}

struct Located {
  const json* schema;
  const json* root;
};

// The subschemas that apply to one value of a document, found by walking the schema along
// the value's pointer the way a validator does. `if` is decided by a small evaluator of the
// keywords conditions use (const, enum, type, required, properties, not, allOf, anyOf);
// under any other keyword both branches count.
class Walker {
 public:
  explicit Walker(const Registry& reg) : reg_(reg) {}

  std::vector<Located> at(const json& doc, std::string_view stem, const Tokens& tokens) const {
    std::vector<Located> out;
    const json& root = reg_.get(stem).doc();
    collect(root, &root, doc, tokens, 0, out, 0);
    return out;
  }

 private:
  Located resolve(const json* s, const json* root, int depth = 0) const {
    while (depth++ < 32 && s->is_object() && s->contains("$ref") && (*s)["$ref"].is_string()) {
      const std::string ref = (*s)["$ref"];
      const size_t hash = ref.find('#');
      if (hash != 0) root = &reg_.get(stem_of(ref)).doc();
      const std::string fragment = hash == std::string::npos ? "" : ref.substr(hash + 1);
      s = &root->at(json::json_pointer(fragment));
    }
    return {s, root};
  }

  void collect(const json& schema, const json* schema_root, const json& value, const Tokens& tokens, size_t k,
               std::vector<Located>& out, int depth) const {
    if (depth > 64) return;
    const auto [s, root] = resolve(&schema, schema_root);
    if (!s->is_object()) return;
    if (k == tokens.size()) {
      out.push_back({s, root});
    } else {
      const std::string& tok = tokens[k];
      static const json absent;
      if (value.is_object() || value.is_null()) {
        // An absent key still has its subschemas (for its default).
        const json& child = value.is_object() && value.contains(tok) ? value[tok] : absent;
        bool matched = false;
        if (s->contains("properties") && (*s)["properties"].contains(tok)) {
          collect((*s)["properties"][tok], root, child, tokens, k + 1, out, depth + 1);
          matched = true;
        }
        if (s->contains("patternProperties"))
          for (const auto& [pattern, sub] : (*s)["patternProperties"].items())
            if (std::regex_search(tok, std::regex(pattern, std::regex::ECMAScript))) {
              collect(sub, root, child, tokens, k + 1, out, depth + 1);
              matched = true;
            }
        if (!matched && s->contains("additionalProperties") && (*s)["additionalProperties"].is_object())
          collect((*s)["additionalProperties"], root, child, tokens, k + 1, out, depth + 1);
      } else if (value.is_array() && !tok.empty() && tok.find_first_not_of("0123456789") == std::string::npos &&
                 std::stoul(tok) < value.size()) {
        const size_t i = std::stoul(tok);
        const json& child = value[i];
        if (s->contains("items")) {
          const json& items = (*s)["items"];
          if (items.is_object()) collect(items, root, child, tokens, k + 1, out, depth + 1);
          else if (items.is_array() && i < items.size()) collect(items[i], root, child, tokens, k + 1, out, depth + 1);
          else if (items.is_array() && s->contains("additionalItems"))
            collect((*s)["additionalItems"], root, child, tokens, k + 1, out, depth + 1);
        }
      }
    }
    for (const char* key : {"allOf", "anyOf", "oneOf"})
      if (s->contains(key))
        for (const auto& sub : (*s)[key]) collect(sub, root, value, tokens, k, out, depth + 1);
    if (s->contains("if")) {
      const std::optional<bool> holds = matches((*s)["if"], root, value);
      if (holds.value_or(true) && s->contains("then")) collect((*s)["then"], root, value, tokens, k, out, depth + 1);
      if (!holds.value_or(false) && s->contains("else")) collect((*s)["else"], root, value, tokens, k, out, depth + 1);
    }
    if (s->contains("dependencies") && value.is_object())
      for (const auto& [name, sub] : (*s)["dependencies"].items())
        if (sub.is_object() && value.contains(name)) collect(sub, root, value, tokens, k, out, depth + 1);
  }

 public:
  // Whether `value` satisfies the subschema; nullopt when it uses keywords this does not know.
  std::optional<bool> matches(const json& schema, const json* schema_root, const json& value, int depth = 0) const {
    if (depth > 64) return std::nullopt;
    const auto [s, root] = resolve(&schema, schema_root);
    if (s->is_boolean()) return s->get<bool>();
    if (!s->is_object()) return std::nullopt;
    bool unknown = false;
    auto fold = [&](std::optional<bool> r) {
      if (!r) unknown = true;
      return r == false;
    };
    for (const auto& [key, arg] : s->items()) {
      if (key == "description" || key == "title" || key == "$comment" || key == "errorMessage" || key == "default" ||
          key == "examples" || key == "definitions" || key == "$schema" || key == kEnoughKeyword) {
        continue;
      } else if (key == "const") {
        if (value != arg) return false;
      } else if (key == "enum") {
        if (std::find(arg.begin(), arg.end(), value) == arg.end()) return false;
      } else if (key == "type") {
        if (!types_match(value, arg)) return false;
      } else if (key == "required") {
        if (value.is_object())
          for (const auto& name : arg)
            if (!value.contains(name.get<std::string>())) return false;
      } else if (key == "properties") {
        if (value.is_object())
          for (const auto& [name, sub] : arg.items())
            if (value.contains(name) && fold(matches(sub, root, value[name], depth + 1))) return false;
      } else if (key == "not") {
        const auto r = matches(arg, root, value, depth + 1);
        if (r == true) return false;
        if (!r) unknown = true;
      } else if (key == "allOf") {
        for (const auto& sub : arg)
          if (fold(matches(sub, root, value, depth + 1))) return false;
      } else if (key == "anyOf") {
        bool any = false, all_known = true;
        for (const auto& sub : arg) {
          const auto r = matches(sub, root, value, depth + 1);
          any |= r == true;
          all_known &= r.has_value();
        }
        if (!any && all_known) return false;
        if (!any) unknown = true;
      } else {
        unknown = true;
      }
    }
    if (unknown) return std::nullopt;
    return true;
  }

 private:
  const Registry& reg_;
};

// ---- plain sentences

std::string type_phrase(const json& type) {
  auto one = [](const std::string& t) -> std::string {
    if (t == "integer") return "an integer";
    if (t == "number") return "a number";
    if (t == "string") return "a string";
    if (t == "object") return "an object";
    if (t == "array") return "an array";
    if (t == "boolean") return "true or false";
    if (t == "null") return "null";
    return t;
  };
  if (type.is_string()) return one(type.get<std::string>());
  std::string s;
  for (size_t i = 0; i < type.size(); ++i)
    s += (i ? (i + 1 == type.size() ? " or " : ", ") : "") + one(type[i].get<std::string>());
  return s;
}

std::string list_values(const json& values) {
  std::string s;
  for (size_t i = 0; i < values.size(); ++i) s += (i ? ", " : "") + values[i].dump();
  return s;
}

std::string items_text(size_t n) { return std::to_string(n) + (n == 1 ? " item" : " items"); }

bool is_index(const std::string& t) { return !t.empty() && t.find_first_not_of("0123456789") == std::string::npos; }

std::string pointer_of(const Tokens& tokens) {
  if (tokens.empty()) return "/";
  std::string p;
  for (const auto& t : tokens) {
    p += '/';
    for (char c : t) p += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
  }
  return p;
}

// What valijson's description says failed.
enum class Failure {
  wrapper,
  required,
  unknown_key,
  not_,
  type,
  enum_,
  const_,
  minimum,
  exclusive_minimum,
  maximum,
  exclusive_maximum,
  min_items,
  max_items,
  min_length,
  max_length,
  min_properties,
  max_properties,
  pattern,
  multiple_of,
  unique_items,
  one_of,
  format,
  other
};

struct Classified {
  Failure failure;
  const char* keyword;
  std::string name;  // the property of required / unknown_key
};

Classified classify(const std::string& d) {
  auto starts = [&](const char* p) { return d.rfind(p, 0) == 0; };
  auto quoted = [&] {
    const size_t b = d.find('\''), e = d.rfind('\'');
    return b != std::string::npos && e > b ? d.substr(b + 1, e - b - 1) : std::string();
  };
  if (starts("Failed to validate against exactly one child schema")) return {Failure::one_of, "oneOf", ""};
  if (starts("Failed to validate")) return {Failure::wrapper, "", ""};
  if (starts("Missing required property")) return {Failure::required, "required", quoted()};
  if (starts("Object contains a property that could not be validated")) {
    const size_t e = d.rfind('\''), b = d.rfind('\'', e - 1);
    return {Failure::unknown_key, "additionalProperties", d.substr(b + 1, e - b - 1)};
  }
  if (starts("Target should not validate")) return {Failure::not_, "not", ""};
  if (starts("Value type not permitted")) return {Failure::type, "type", ""};
  if (starts("Failed to match against any enum")) return {Failure::enum_, "enum", ""};
  if (starts("Failed to match expected value set by 'const'")) return {Failure::const_, "const", ""};
  if (starts("Expected number less than or equal to")) return {Failure::maximum, "maximum", ""};
  if (starts("Expected number less than")) return {Failure::exclusive_maximum, "exclusiveMaximum", ""};
  if (starts("Expected number greater than or equal to")) return {Failure::minimum, "minimum", ""};
  if (starts("Expected number greater than")) return {Failure::exclusive_minimum, "exclusiveMinimum", ""};
  if (starts("Array should contain no fewer")) return {Failure::min_items, "minItems", ""};
  if (starts("Array should contain no more")) return {Failure::max_items, "maxItems", ""};
  if (starts("String should be no fewer")) return {Failure::min_length, "minLength", ""};
  if (starts("String should be no more")) return {Failure::max_length, "maxLength", ""};
  if (starts("Object should have no fewer")) return {Failure::min_properties, "minProperties", ""};
  if (starts("Object should have no more")) return {Failure::max_properties, "maxProperties", ""};
  if (starts("Failed to match regex")) return {Failure::pattern, "pattern", ""};
  if (starts("Value should be a multiple of")) return {Failure::multiple_of, "multipleOf", ""};
  if (d.find("uniqueness constraint") != std::string::npos) return {Failure::unique_items, "uniqueItems", ""};
  if (starts("String should be a valid")) return {Failure::format, "format", ""};
  return {Failure::other, "", ""};
}

// Whether subschema `s`'s keyword fails for `value` (so that the sentence names the bound or
// the list that the value missed, when several subschemas apply).
bool keyword_fails(const Classified& c, const json& s, const json& value, const Walker& walker, const json* root) {
  const json& arg = s[c.keyword];
  switch (c.failure) {
    case Failure::required:
      return std::find(arg.begin(), arg.end(), c.name) != arg.end();
    case Failure::not_:
      return walker.matches(arg, root, value).value_or(true);
    case Failure::type:
      return !types_match(value, arg);
    case Failure::enum_:
      return std::find(arg.begin(), arg.end(), value) == arg.end();
    case Failure::const_:
      return value != arg;
    case Failure::minimum:
      return value.is_number() && value.get<double>() < arg.get<double>();
    case Failure::exclusive_minimum:
      return value.is_number() && value.get<double>() <= arg.get<double>();
    case Failure::maximum:
      return value.is_number() && value.get<double>() > arg.get<double>();
    case Failure::exclusive_maximum:
      return value.is_number() && value.get<double>() >= arg.get<double>();
    case Failure::min_items:
    case Failure::min_properties:
      return value.size() < arg.get<size_t>();
    case Failure::max_items:
    case Failure::max_properties:
      return value.size() > arg.get<size_t>();
    case Failure::min_length:
      return value.is_string() && value.get<std::string>().size() < arg.get<size_t>();
    case Failure::max_length:
      return value.is_string() && value.get<std::string>().size() > arg.get<size_t>();
    case Failure::pattern:
      return value.is_string() && !std::regex_search(value.get<std::string>(), std::regex(arg.get<std::string>()));
    default:
      return true;
  }
}

class Describer {
 public:
  Describer(const json& doc, std::string_view stem) : doc_(doc), stem_(stem), walker_(registry()) {}

  SceneIssue issue(Tokens tokens, const std::string& description) const {
    const Classified c = classify(description);
    // Required and unknown keys: the schema sits at the object, the pointer names the key.
    const Tokens object_tokens = tokens;
    if (c.failure == Failure::required || c.failure == Failure::unknown_key) tokens.push_back(c.name);
    const json* value = find(tokens);
    const std::string pointer = pointer_of(tokens);
    if (c.failure == Failure::unknown_key) return {pointer, unknown_key(object_tokens, c.name)};

    const std::vector<Located> here = walker_.at(doc_, stem_, object_tokens);
    const Located* chosen = nullptr;
    if (*c.keyword && (value || c.failure == Failure::required)) {
      const json& subject = c.failure == Failure::required ? *find(object_tokens) : *value;
      for (const Located& l : here)
        if (l.schema->contains(c.keyword) && keyword_fails(c, *l.schema, subject, walker_, l.root)) {
          // Prefer the subschema that explains itself.
          if (!chosen || (!chosen->schema->contains("errorMessage") && l.schema->contains("errorMessage"))) chosen = &l;
        }
    }
    if (chosen && chosen->schema->contains("errorMessage") && (*chosen->schema)["errorMessage"].is_string())
      return {pointer, (*chosen->schema)["errorMessage"].get<std::string>()};
    return {pointer, sentence(c, value, chosen ? chosen->schema : nullptr, tokens, description)};
  }

 private:
  const json* find(const Tokens& tokens) const {
    const json* v = &doc_;
    for (const auto& t : tokens) {
      if (v->is_object() && v->contains(t)) v = &(*v)[t];
      else if (v->is_array() && is_index(t) && std::stoul(t) < v->size()) v = &(*v)[std::stoul(t)];
      else return nullptr;
    }
    return v;
  }

  // A key that no subschema allows; "not allowed here" for a known key that a condition
  // forbids (with the reason, when the schema gives one, through errorMessage).
  std::string unknown_key(const Tokens& object_tokens, const std::string& name) const {
    std::vector<std::string> known;
    bool known_here = false;
    for (const Located& l : walker_.at(doc_, stem_, object_tokens)) {
      if (!l.schema->contains("properties")) continue;
      for (const auto& [key, sub] : (*l.schema)["properties"].items()) {
        const bool forbidden = sub.is_object() && sub.contains("not") && sub["not"].empty();
        if (forbidden) continue;
        known_here |= key == name;
        if (std::find(known.begin(), known.end(), key) == known.end()) known.push_back(key);
      }
    }
    if (known_here) return "is not allowed here";
    std::sort(known.begin(), known.end());
    std::string list;
    for (size_t i = 0; i < known.size(); ++i) list += (i ? ", " : "") + ("\"" + known[i] + "\"");
    return "is not a known key" + (known.empty() ? std::string() : " (expected one of " + list + ")");
  }

  std::string sentence(const Classified& c, const json* value, const json* s, const Tokens& tokens,
                       const std::string& description) const {
    const std::string v = value ? show(*value) : "the value";
    const json* arg = s ? &(*s)[c.keyword] : nullptr;
    switch (c.failure) {
      case Failure::required:
        return "is required";
      case Failure::not_:
        if (arg && arg->empty())
          return tokens.empty() ? "is not allowed" : unknown_key({tokens.begin(), tokens.end() - 1}, tokens.back());
        if (arg && arg->contains("const")) return "must not be " + (*arg)["const"].dump();
        if (arg && arg->contains("enum")) return "must not be " + list_values((*arg)["enum"]);
        return v + " has a form that is not allowed here";
      case Failure::type:
        return arg ? v + " is not " + type_phrase(*arg) : v + " has the wrong type";
      case Failure::enum_:
        return arg ? v + " is not one of " + list_values(*arg) : v + " is not one of the allowed values";
      case Failure::const_:
        return arg ? v + " is not " + arg->dump() : v + " is not the expected value";
      case Failure::minimum:
        if (!arg) break;
        return *arg == 0 ? v + " is negative" : v + " is below " + arg->dump();
      case Failure::exclusive_minimum:
        if (!arg) break;
        return *arg == 0 ? v + " is not positive" : v + " is not above " + arg->dump();
      case Failure::maximum:
        if (!arg) break;
        return v + " is above " + arg->dump();
      case Failure::exclusive_maximum:
        if (!arg) break;
        return v + " is not below " + arg->dump();
      case Failure::min_items:
        if (!arg || !value) break;
        return "has " + items_text(value->size()) + "; at least " + arg->dump() + " needed";
      case Failure::max_items:
        if (!arg || !value) break;
        return "has " + items_text(value->size()) + "; at most " + arg->dump() + " allowed";
      case Failure::min_properties:
        if (!arg) break;
        return "needs at least " + arg->dump() + " keys";
      case Failure::max_properties:
        if (!arg) break;
        return "has more than " + arg->dump() + " keys";
      case Failure::min_length:
        if (!arg) break;
        return *arg == 1 ? "is empty" : v + " is shorter than " + arg->dump() + " characters";
      case Failure::max_length:
        if (!arg) break;
        return v + " is longer than " + arg->dump() + " characters";
      case Failure::pattern:
        if (!arg) break;
        return v + " does not match " + arg->dump();
      case Failure::multiple_of:
        if (!arg) break;
        return v + " is not a multiple of " + arg->dump();
      case Failure::unique_items:
        return "has equal items (" + description + ")";
      case Failure::one_of:
        return v + " matches more than one of the allowed forms";
      case Failure::format:
        return v + " is not a valid " + (arg && arg->is_string() ? arg->get<std::string>() : "value");
      default:
        break;
    }
    return description;
  }

  const json& doc_;
  std::string_view stem_;
  Walker walker_;
};

bool pointer_less(const Tokens& a, const Tokens& b) {
  const size_t n = std::min(a.size(), b.size());
  for (size_t i = 0; i < n; ++i) {
    if (a[i] == b[i]) continue;
    if (is_index(a[i]) && is_index(b[i]) && a[i].size() != b[i].size()) return a[i].size() < b[i].size();
    return a[i] < b[i];
  }
  return a.size() < b.size();
}

Tokens tokens_of(const std::vector<std::string>& context) {
  Tokens t;
  for (const auto& c : context)
    if (c.size() >= 2 && c.front() == '[' && c.back() == ']') t.push_back(c.substr(1, c.size() - 2));
  return t;
}

}  // namespace

std::string_view schema_file_stem(SchemaName which) {
  switch (which) {
    case SchemaName::scene:
      return "scene";
    case SchemaName::event:
      return "event";
    case SchemaName::result:
      return "result";
    case SchemaName::job:
      return "job";
  }
  throw std::invalid_argument("unknown SchemaName");
}

std::string_view schema_text(SchemaName which) { return registry().get(schema_file_stem(which)).text; }

std::optional<nlohmann::json> schema_default(const nlohmann::json& document, SchemaName which,
                                             std::string_view pointer) {
  Tokens tokens;
  if (pointer != "/" && !pointer.empty()) {
    if (pointer.front() != '/') throw std::invalid_argument("not a JSON pointer: " + std::string(pointer));
    for (size_t at = 1; at <= pointer.size();) {
      const size_t end = std::min(pointer.find('/', at), pointer.size());
      std::string t;
      for (size_t i = at; i < end; ++i)
        if (pointer[i] == '~' && i + 1 < end) t += pointer[++i] == '1' ? '/' : '~';
        else t += pointer[i];
      tokens.push_back(t);
      at = end + 1;
    }
  }
  const Walker walker(registry());
  for (const Located& l : walker.at(document, schema_file_stem(which), tokens))
    if (l.schema->contains("default")) return (*l.schema)["default"];
  return std::nullopt;
}

void prepare_schema(SchemaName which) {
  const std::string_view stem = schema_file_stem(which);
  registry().get(stem).schema(registry(), stem);
}

std::vector<SceneIssue> validate_against(const nlohmann::json& document, SchemaName which, bool* more) {
  const std::string_view stem = schema_file_stem(which);
  const valijson::Schema& schema = registry().get(stem).schema(registry(), stem);
  valijson::Validator validator(valijson::Validator::kStrongTypes);
  const valijson::adapters::NlohmannJsonAdapter target(document);
  if (more) *more = false;
  // First without collecting: a valid document is answered by one pass that keeps nothing.
  if (validator.validate(schema, target, nullptr)) return {};
  valijson::ValidationResults results;
  bool stopped = false;
  try {
    validator.validate(schema, target, &results);
  } catch (const Enough& enough) {
    for (const auto& e : enough.errors) results.pushError(e);
    stopped = true;
  }

  struct Raw {
    Tokens tokens;         // of the issue's pointer, for sorting
    Tokens object_tokens;  // of the value the schema applies to (the object, for a key)
    std::string description;
  };
  std::vector<Raw> raw;
  std::optional<Tokens> deepest_wrapper;
  valijson::ValidationResults::Error e;
  while (results.popError(e)) {
    Tokens tokens = tokens_of(e.context);
    const Classified c = classify(e.description);
    if (c.failure == Failure::wrapper) {
      if (!deepest_wrapper || tokens.size() > deepest_wrapper->size()) deepest_wrapper = tokens;
      continue;
    }
    Tokens object_tokens = tokens;
    if (c.failure == Failure::required || c.failure == Failure::unknown_key) tokens.push_back(c.name);
    raw.push_back({std::move(tokens), std::move(object_tokens), std::move(e.description)});
  }
  // Only wrappers (a subschema that fails without saying why): name the deepest place.
  if (raw.empty() && deepest_wrapper) return {{pointer_of(*deepest_wrapper), "is not valid"}};
  std::stable_sort(raw.begin(), raw.end(), [](const Raw& a, const Raw& b) { return pointer_less(a.tokens, b.tokens); });
  // Described in pointer order, each once, up to kMaxSceneIssues.
  const Describer describer(document, stem);
  std::vector<SceneIssue> issues;
  std::set<std::pair<std::string, std::string>> seen;
  for (size_t i = 0; i < raw.size(); ++i) {
    if (issues.size() == kMaxSceneIssues) {
      stopped = true;
      break;
    }
    SceneIssue issue = describer.issue(raw[i].object_tokens, raw[i].description);
    if (seen.emplace(issue.pointer, issue.detail).second) issues.push_back(std::move(issue));
  }
  if (more) *more = stopped;
  return issues;
}

}  // namespace grip