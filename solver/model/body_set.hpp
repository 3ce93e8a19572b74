#pragma once
// Several deformable bodies as one: their dofs, sites and nodes one after another, each body
// at its own offsets. The stiffness is block diagonal, so C = T^T K^-1 T is the sum of the
// bodies' compliances and the factorization of K is the bodies' factorizations. A scene of
// one body does not use this (its body stays the Problem's body, at no cost).
#include <memory>
#include <string>
#include <vector>

#include "solver/model/body.hpp"

namespace grip {

class BodySet final : public Body {
 public:
  BodySet(std::vector<std::unique_ptr<Body>> parts, std::vector<std::string> names);

  int part_count() const override { return static_cast<int>(parts_.size()); }
  const Body& part(int b) const override { return *parts_[b]; }
  Body& mutable_part(int b) { return *parts_[b]; }  // to set a part up before the solve
  const std::string& name(int b) const { return names_[b]; }
  int dof_offset(int b) const override { return dof_offset_[b]; }
  int site_offset(int b) const override { return site_offset_[b]; }
  int node_offset(int b) const { return node_offset_[b]; }
  // The body a site (or a node) of the set belongs to.
  int body_of_site(int site) const;
  int body_of_node(int node) const;
  // The part of q that belongs to body b.
  Vector part_q(const Vector& q, int b) const { return q.segment(dof_offset_[b], parts_[b]->dof_count()); }

  int dof_count() const override { return dof_offset_.back(); }
  Vector dof_length_scales() const override;
  void internal_force(const Vector& q, Vector& force, TangentSink* tangent) const override;
  int site_count() const override { return site_offset_.back(); }
  int node_count() const override { return node_offset_.back(); }
  Vec2 site_reference(int site) const override;
  int site_node(int site) const override;
  SurfacePoint surface_point(const VectorRef& q, int site, int side) const override;
  void surface_point_into(const VectorRef& q, int site, int side, SurfacePoint& out) const override;
  std::vector<std::array<int, 2>> surface_segments() const override;
  std::vector<int> nodes_without_site() const override;
  Vec2 node_position(const VectorRef& q, int node) const override;
  double tributary_area(int site) const override;
  double characteristic_length() const override;
  // The whole set translated, or rotated (when every body has a rotation).
  Vector rigid_translation(const Vec2& d) const override;
  Vector rigid_rotation() const override;
  Traits traits() const override;
  // The scene reader refuses a set that mixes sections of revolution with plane bodies.
  bool axisymmetric() const override { return !parts_.empty() && parts_[0]->axisymmetric(); }
  std::optional<ElementQuality> element_quality() const override;
  std::vector<std::vector<int>> cells() const override;
  FieldTable site_fields(const Vector& q) const override;
  FieldTable element_fields(const Vector& q) const override;
  Vector start_guess(const Vector& prescribed, const std::vector<char>& is_prescribed) const override;
  double newton_step_fraction(const Vector& q, const Vector& dq) const override;
  std::string inadmissible(const Vector& q) const override;
  std::string validity_warning(const Vector& q) const override;
  void commit(const Vector& q) override;
  std::string update_multipliers(const Vector& q) override;

 private:
  // The parts' tables of `fields` one below the other, with every part's columns; a column
  // that a part lacks (a beam's theta on a continuum's rows) is NaN there, which the result
  // leaves out of that row.
  FieldTable stacked(FieldTable (Body::*fields)(const Vector&) const, const Vector& q) const;
  std::vector<std::unique_ptr<Body>> parts_;
  std::vector<std::string> names_;
  std::vector<int> dof_offset_, site_offset_, node_offset_;  // count() + 1 entries each
};

}  // namespace grip
