#include "solver/model/body_set.hpp"

#include <algorithm>
#include <limits>

namespace grip {

BodySet::BodySet(std::vector<std::unique_ptr<Body>> parts, std::vector<std::string> names)
    : parts_(std::move(parts)), names_(std::move(names)) {
  dof_offset_ = site_offset_ = node_offset_ = {0};
  for (const auto& p : parts_) {
    dof_offset_.push_back(dof_offset_.back() + p->dof_count());
    site_offset_.push_back(site_offset_.back() + p->site_count());
    node_offset_.push_back(node_offset_.back() + p->node_count());
  }
}

namespace {
// The entry b of ascending offsets with offsets[b] <= i < offsets[b + 1].
int find_part(const std::vector<int>& offsets, int i) {
  return static_cast<int>(std::upper_bound(offsets.begin(), offsets.end(), i) - offsets.begin()) - 1;
}
}  // namespace

int BodySet::body_of_site(int site) const { return find_part(site_offset_, site); }
int BodySet::body_of_node(int node) const { return find_part(node_offset_, node); }

Vector BodySet::dof_length_scales() const {
  Vector s(dof_count());
  for (int b = 0; b < part_count(); ++b)
    s.segment(dof_offset_[b], parts_[b]->dof_count()) = parts_[b]->dof_length_scales();
  return s;
}

namespace {

// A part's entries, passed on at its rows in the set.
class OffsetSink final : public TangentSink {
 public:
  OffsetSink(TangentSink* out, int offset) : out_(out), offset_(offset) {}
  void add(int row, int col, double value) override { out_->add(row + offset_, col + offset_, value); }
  void add_block(const int* dofs, const Matrix& block) override {
    shifted_.resize(block.rows());
    for (size_t i = 0; i < shifted_.size(); ++i) shifted_[i] = dofs[i] + offset_;
    out_->add_block(shifted_.data(), block);
  }

 private:
  TangentSink* out_;
  int offset_;
  std::vector<int> shifted_;
};

}  // namespace

void BodySet::internal_force(const Vector& q, Vector& force, TangentSink* tangent) const {
  for (int b = 0; b < part_count(); ++b) {
    const int n = parts_[b]->dof_count(), o = dof_offset_[b];
    Vector f = Vector::Zero(n);
    OffsetSink part_tangent(tangent, o);
    const Vector base = tangent && tangent->stress_base ? Vector(part_q(*tangent->stress_base, b)) : Vector();
    if (base.size()) part_tangent.stress_base = &base;
    parts_[b]->internal_force(part_q(q, b), f, tangent ? &part_tangent : nullptr);
    force.segment(o, n) += f;
  }
}

Vec2 BodySet::site_reference(int site) const {
  const int b = body_of_site(site);
  return parts_[b]->site_reference(site - site_offset_[b]);
}

int BodySet::site_node(int site) const {
  const int b = body_of_site(site);
  return node_offset_[b] + parts_[b]->site_node(site - site_offset_[b]);
}

std::vector<int> BodySet::nodes_without_site() const {
  std::vector<int> out;
  for (int b = 0; b < part_count(); ++b)
    for (int node : parts_[b]->nodes_without_site()) out.push_back(node_offset_[b] + node);
  return out;
}

Vec2 BodySet::node_position(const VectorRef& q, int node) const {
  const int b = body_of_node(node);
  return parts_[b]->node_position(q.segment(dof_offset_[b], parts_[b]->dof_count()), node - node_offset_[b]);
}

SurfacePoint BodySet::surface_point(const VectorRef& q, int site, int side) const {
  const int b = body_of_site(site);
  // A view of the body's part of q: a copy of it per point made pairing quadratic (12 % of the
  // 1501-point interface's time).
  SurfacePoint p =
      parts_[b]->surface_point(q.segment(dof_offset_[b], parts_[b]->dof_count()), site - site_offset_[b], side);
  for (auto& j : p.jacobian) j.dof += dof_offset_[b];
  return p;
}

void BodySet::surface_point_into(const VectorRef& q, int site, int side, SurfacePoint& out) const {
  const int b = body_of_site(site);
  parts_[b]->surface_point_into(q.segment(dof_offset_[b], parts_[b]->dof_count()), site - site_offset_[b], side, out);
  for (auto& j : out.jacobian) j.dof += dof_offset_[b];
}

std::vector<std::array<int, 2>> BodySet::surface_segments() const {
  std::vector<std::array<int, 2>> all;
  for (int b = 0; b < part_count(); ++b)
    for (const auto& s : parts_[b]->surface_segments()) all.push_back({s[0] + site_offset_[b], s[1] + site_offset_[b]});
  return all;
}

double BodySet::tributary_area(int site) const {
  const int b = body_of_site(site);
  return parts_[b]->tributary_area(site - site_offset_[b]);
}

double BodySet::characteristic_length() const {
  double L = 0.0;
  for (const auto& p : parts_) L = std::max(L, p->characteristic_length());
  return L;
}

Vector BodySet::rigid_translation(const Vec2& d) const {
  Vector t(dof_count());
  for (int b = 0; b < part_count(); ++b)
    t.segment(dof_offset_[b], parts_[b]->dof_count()) = parts_[b]->rigid_translation(d);
  return t;
}

Vector BodySet::rigid_rotation() const {
  Vector r(dof_count());
  for (int b = 0; b < part_count(); ++b) {
    const Vector part = parts_[b]->rigid_rotation();
    if (part.size() == 0) return {};
    r.segment(dof_offset_[b], part.size()) = part;
  }
  return r;
}

Body::Traits BodySet::traits() const {
  Traits t{false, false, true, true, true};
  bool changing = false;  // some part's tangent changes
  for (const auto& p : parts_) {
    const Traits pt = p->traits();
    // Newton's corrections are taken in full only where every changing tangent takes the
    // linearized stress (newton.cpp).
    if (!pt.constant_tangent) {
      changing = true;
      t.linearized_stress &= pt.linearized_stress;
    }
    t.geometric_nonlinearity |= pt.geometric_nonlinearity;
    t.plasticity |= pt.plasticity;
    t.constant_tangent &= pt.constant_tangent;
    t.reference_stiffness &= pt.reference_stiffness;
    t.volume_constrained |= pt.volume_constrained;
  }
  t.linearized_stress &= changing;
  return t;
}

std::optional<ElementQuality> BodySet::element_quality() const {
  std::optional<ElementQuality> all;
  for (const auto& p : parts_) {
    const auto q = p->element_quality();
    if (!q) continue;
    if (!all) {
      all = q;
      continue;
    }
    all->elements += q->elements;
    all->max_aspect_ratio = std::max(all->max_aspect_ratio, q->max_aspect_ratio);
    all->min_angle = std::min(all->min_angle, q->min_angle);
    all->max_angle = std::max(all->max_angle, q->max_angle);
  }
  return all;
}

std::vector<std::vector<int>> BodySet::cells() const {
  std::vector<std::vector<int>> all;
  for (int b = 0; b < part_count(); ++b)
    for (auto cell : parts_[b]->cells()) {
      for (int& n : cell) n += node_offset_[b];
      all.push_back(std::move(cell));
    }
  return all;
}

FieldTable BodySet::stacked(FieldTable (Body::*fields)(const Vector&) const, const Vector& q) const {
  FieldTable all;
  std::vector<FieldTable> tables;
  for (int b = 0; b < part_count(); ++b) {
    tables.push_back((parts_[b].get()->*fields)(part_q(q, b)));
    for (const std::string& name : tables.back().names)
      if (std::find(all.names.begin(), all.names.end(), name) == all.names.end()) all.names.push_back(name);
  }
  for (FieldTable& t : tables) {
    std::vector<size_t> column;
    for (const std::string& name : t.names)
      column.push_back(std::find(all.names.begin(), all.names.end(), name) - all.names.begin());
    for (const auto& row : t.rows) {
      std::vector<double> wide(all.names.size(), std::numeric_limits<double>::quiet_NaN());
      for (size_t c = 0; c < row.size(); ++c) wide[column[c]] = row[c];
      all.rows.push_back(std::move(wide));
    }
  }
  return all;
}

FieldTable BodySet::site_fields(const Vector& q) const { return stacked(&Body::site_fields, q); }

FieldTable BodySet::element_fields(const Vector& q) const { return stacked(&Body::element_fields, q); }

Vector BodySet::start_guess(const Vector& prescribed, const std::vector<char>& is_prescribed) const {
  Vector q(dof_count());
  for (int b = 0; b < part_count(); ++b) {
    const int o = dof_offset_[b], n = parts_[b]->dof_count();
    const std::vector<char> part(is_prescribed.begin() + o, is_prescribed.begin() + o + n);
    q.segment(o, n) = parts_[b]->start_guess(part_q(prescribed, b), part);
  }
  return q;
}

double BodySet::newton_step_fraction(const Vector& q, const Vector& dq) const {
  double a = 1.0;
  for (int b = 0; b < part_count(); ++b) a = std::min(a, parts_[b]->newton_step_fraction(part_q(q, b), part_q(dq, b)));
  return a;
}

std::string BodySet::inadmissible(const Vector& q) const {
  for (int b = 0; b < part_count(); ++b)
    if (std::string why = parts_[b]->inadmissible(part_q(q, b)); !why.empty()) return names_[b] + ": " + why;
  return {};
}

std::string BodySet::validity_warning(const Vector& q) const {
  for (int b = 0; b < part_count(); ++b)
    if (std::string why = parts_[b]->validity_warning(part_q(q, b)); !why.empty()) return names_[b] + ": " + why;
  return {};
}

void BodySet::commit(const Vector& q) {
  for (int b = 0; b < part_count(); ++b) parts_[b]->commit(part_q(q, b));
}

std::string BodySet::update_multipliers(const Vector& q) {
  std::string off;
  for (int b = 0; b < part_count(); ++b)
    if (const std::string why = parts_[b]->update_multipliers(part_q(q, b)); !why.empty())
      off += (off.empty() ? "" : "; ") + names_[b] + ": " + why;
  return off;
}

}  // namespace grip
