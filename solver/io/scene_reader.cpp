#include "solver/io/scene_reader.hpp"

namespace grip::scene_io {

void read_supports(Reader& r, json& body, const std::string& ptr, int nodes, const std::vector<std::string>& components,
                   int (*dof)(int, int), Problem& problem) {
  if (json* sup = r.array(body, ptr, "supports", false))
    for (size_t i = 0; i < sup->size(); ++i) {
      const std::string sp = ptr + "/supports/" + std::to_string(i);
      json& s = (*sup)[i];
      if (!s.is_object()) {
        r.error(sp, "is not an object");
        continue;
      }
      const int node = r.integer(s, sp, "node", 0, nodes - 1);
      const int load_case = r.load_case(s, sp);
      json* fix = r.array(s, sp, "fix", true);
      json* values = r.object(s, sp, "values", false);
      if (!fix) continue;
      for (size_t c = 0; c < fix->size(); ++c) {
        const json& comp = (*fix)[c];
        int index = -1;
        for (size_t k = 0; k < components.size(); ++k)
          if (comp == components[k]) index = static_cast<int>(k);
        if (index < 0) {
          r.error(sp + "/fix/" + std::to_string(c), show(comp) + " is not one of " + Reader::list(components));
          continue;
        }
        const std::string name = comp.get<std::string>();
        bool repeated = false;
        for (const Constraint& other : problem.constraints) repeated |= other.dof == dof(node, index);
        if (repeated) {
          r.error(sp + "/fix/" + std::to_string(c),
                  "\"" + name + "\" of node " + std::to_string(node) + " is fixed already");
          continue;
        }
        double value = 0.0;
        if (values && values->contains(name)) value = r.number(*values, sp + "/values", name.c_str());
        problem.constraints.push_back({dof(node, index), value, load_case});
      }
      if (values)
        for (const auto& [name, v] : values->items()) {
          bool fixed = false;
          for (const auto& comp : *fix) fixed |= comp == name;
          if (!fixed) r.error(sp + "/values/" + token(name), "is given but \"" + name + "\" is not in fix");
        }
    }
}

}  // namespace grip::scene_io
