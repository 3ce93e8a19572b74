#include "solver/io/scene.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "solver/io/gmsh_mesh.hpp"
#include "solver/io/json_depth.hpp"
#include "solver/io/scene_reader.hpp"
#include "solver/io/schema_validation.hpp"
#include "solver/model/body_set.hpp"
#include "solver/model/number_text.hpp"
#include "solver/problem/rigid_modes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using scene_io::Reader;
using scene_io::show;
using scene_io::token;

std::string join(const std::vector<SceneIssue>& issues) {
  std::ostringstream os;
  for (size_t i = 0; i < issues.size(); ++i) os << (i ? "\n" : "") << issues[i].pointer << ": " << issues[i].detail;
  return os.str();
}

// ---- obstacles

ProfilePiece read_piece(Reader& r, json& j, const std::string& ptr) {
  const std::string type = r.choice(j, ptr, "type", {"segment", "arc"}, std::nullopt);
  if (type == "segment") return SegmentPiece{r.vec2(j, ptr, "from"), r.vec2(j, ptr, "to")};
  const double deg = std::numbers::pi / 180;
  return ArcPiece{r.vec2(j, ptr, "centre"), r.positive(j, ptr, "radius"), r.number(j, ptr, "start_angle") * deg,
                  r.number(j, ptr, "end_angle") * deg};
}

std::unique_ptr<Obstacle> read_shape(Reader& r, json& j, const std::string& ptr) {
  const std::string type =
      r.choice(j, ptr, "type", {"circle", "segment", "arc", "profile", "gmsh_curve"}, std::nullopt);
  const size_t before = r.issues.size();
  std::vector<ProfilePiece> pieces;
  if (type == "gmsh_curve") {
    auto curve = scene_io::read_curve_pieces(r, j, ptr);
    if (!curve) return nullptr;
    pieces = std::move(*curve);
  }
  if (type == "circle") {
    const Vec2 c = r.vec2(j, ptr, "centre");
    const double radius = r.positive(j, ptr, "radius");
    if (r.issues.size() > before) return nullptr;
    return make_circle(c, radius);
  }
  if (type == "profile") {
    json* arr = r.array(j, ptr, "pieces", true);
    if (arr && arr->empty()) r.error(ptr + "/pieces", "needs at least one piece");
    if (arr)
      for (size_t i = 0; i < arr->size(); ++i) {
        const std::string pp = ptr + "/pieces/" + std::to_string(i);
        if (!(*arr)[i].is_object()) {
          r.error(pp, "is not an object");
          continue;
        }
        pieces.push_back(read_piece(r, (*arr)[i], pp));
      }
  } else if (type != "gmsh_curve") {
    pieces.push_back(read_piece(r, j, ptr));
  }
  if (r.issues.size() > before) return nullptr;
  try {
    return make_profile(std::move(pieces));
  } catch (const std::invalid_argument& e) {
    r.error(ptr, e.what());
    return nullptr;
  }
}

// ---- solver parameters

// solver.start: {"node", "component": "x" | "y", "value", "obstacle"} (the obstacle that presses
// the node, if one does)
// (docs/algorithm.md#load-stepping-and-cuts): the first step starts from a solve with that
// displacement prescribed and no contact.
void read_start(Reader& r, json& scene, Problem& problem) {
  const bool membrane = scene.contains("body") && scene["body"].is_object() &&
                        scene["body"].value("model", "") == "rigid_plastic_membrane";
  json* solver = r.object(scene, "", "solver", false);
  if (!solver) return;
  if (!solver->contains("start")) {
    if (membrane)
      r.error("/solver/start",
              "is required for a rigid_plastic_membrane: a flat sheet has no transverse "
              "stiffness, so its first step starts from a prescribed depth of one node "
              "(e.g. {\"node\": 0, \"component\": \"y\", \"value\": -1, \"obstacle\": \"punch\"})");
    return;
  }
  json* st = r.object(*solver, "/solver", "start", true);
  if (!st || !problem.body) return;
  const std::string sp = "/solver/start";
  const int node = r.integer(*st, sp, "node", 0, problem.body->site_count() - 1);
  const std::string comp = r.choice(*st, sp, "component", {"x", "y"}, "y");
  const double value = r.number(*st, sp, "value");
  if (value == 0.0) r.error(sp + "/value", "must not be zero: the start needs a strained body");
  int obstacle = -1;  // none (a sheet bulged by a pressure): the start is only Newton's first guess
  if (!st->contains("obstacle")) {
  } else if (!(*st)["obstacle"].is_string()) {
    r.error(sp + "/obstacle",
            show((*st)["obstacle"]) + " is not a string: the name of the obstacle the node is pressed by");
  } else {
    for (size_t o = 0; o < problem.obstacles.size(); ++o)
      if (problem.obstacles[o].name == (*st)["obstacle"]) obstacle = static_cast<int>(o);
    if (obstacle < 0) r.error(sp + "/obstacle", show((*st)["obstacle"]) + " names no obstacle");
  }
  // The dof that moves the node along x or y.
  const Vec2 dir = comp == "x" ? Vec2::UnitX() : Vec2::UnitY();
  const SurfacePoint p = problem.body->surface_point(Vector::Zero(problem.body->dof_count()), node, 0);
  int dof = -1;
  for (const auto& j : p.jacobian)
    if (j.dx.isApprox(dir)) dof = j.dof;
  if (dof < 0) r.error(sp + "/component", "does not move node " + std::to_string(node) + " by itself");
  for (const Constraint& c : problem.constraints)
    if (c.dof == dof) r.error(sp + "/node", "that component of node " + std::to_string(node) + " is a support already");
  if (dof >= 0 && (obstacle >= 0 || !st->contains("obstacle"))) problem.start = StartUp{dof, value, node, obstacle};
}

std::string format_point(const Vec2& p) {
  std::ostringstream os;
  os << "(" << p.x() << ", " << p.y() << ")";
  return os.str();
}

// The rigid motions of the body as columns: translation x, translation y, and (where the body
// has one) the rotation about the origin scaled to a length.
std::vector<Vector> body_modes(const Body& body) {
  std::vector<Vector> modes = {body.rigid_translation(Vec2::UnitX()), body.rigid_translation(Vec2::UnitY())};
  if (const Vector rot = body.rigid_rotation(); rot.size()) modes.push_back(rot / body.characteristic_length());
  return modes;
}

// The motion with coefficients c of body_modes() in words.
std::string motion_name(const Vector& coefficients, double L) {
  Vector c = coefficients.normalized();
  for (int m = 0; m < c.size(); ++m)
    if (std::abs(c[m]) < 1e-9) c[m] = 0.0;  // no "-0" or 1e-17 in the words
  const double omega = c.size() > 2 ? c[2] / L : 0.0;
  if (std::abs(omega) * L < 1e-9) {
    const Vec2 d = Vec2(c[0], c[1]).normalized();
    return std::abs(d.y()) < 1e-9   ? "translate along x"
           : std::abs(d.x()) < 1e-9 ? "translate along y"
                                    : "translate along " + format_point(d);
  }
  Vec2 pivot(-c[1] / omega, c[0] / omega);
  for (int d = 0; d < 2; ++d)
    if (std::abs(pivot[d]) < 1e-9 * L) pivot[d] = 0.0;
  return "rotate about " + format_point(pivot);
}

}  // namespace

// The rigid motions the supports leave free, as coefficients of body_modes() (columns).
Matrix scene_io::free_motions(const Body& body, const std::vector<int>& fixed) {
  const std::vector<Vector> modes = body_modes(body);
  // Axisymmetric: the translation along x and the rotation are no motions of the body at all.
  const size_t extra = body.axisymmetric() ? modes.size() - 1 : 0;
  Matrix R = Matrix::Zero(std::max<size_t>(fixed.size() + extra, 1), modes.size());
  for (size_t i = 0; i < fixed.size(); ++i)
    for (size_t m = 0; m < modes.size(); ++m) R(i, m) = modes[m][fixed[i]];
  for (size_t e = 0; e < extra; ++e) R(fixed.size() + e, e == 0 ? 0 : 2) = 1.0;
  Eigen::FullPivLU<Matrix> lu(R);
  lu.setThreshold(1e-9);
  if (lu.rank() == static_cast<Eigen::Index>(modes.size())) return Matrix(modes.size(), 0);
  return lu.kernel();
}

namespace {

// A basis of the free motions (coefficients of body_modes()) that separates the pure
// translations (the x and y axes where both are free) from at most one rotation.
std::vector<Vector> motion_basis(const Matrix& free) {
  std::vector<Vector> basis;
  const int r = static_cast<int>(free.cols());
  if (r == 0) return basis;
  const Matrix K = free.householderQr().householderQ() * Matrix::Identity(free.rows(), r);  // orthonormal
  const Vector w = K.rows() > 2 ? Vector(K.row(2).transpose()) : Vector::Zero(r);
  Matrix translations = K;
  if (w.norm() > 1e-9) {
    const Matrix Q = w.householderQr().householderQ();  // first column along w, the rest across it
    translations = K * Q.rightCols(r - 1);
  }
  if (translations.cols() == 2 && translations.rows() > 2) {
    basis.push_back(Vector::Unit(K.rows(), 0));
    basis.push_back(Vector::Unit(K.rows(), 1));
  } else {
    for (int j = 0; j < translations.cols(); ++j) {
      Vector t = translations.col(j);
      if (t.size() > 2) t[2] = 0.0;
      basis.push_back(t.normalized());
    }
  }
  if (w.norm() > 1e-9) basis.push_back((K * w).normalized());
  return basis;
}

// The bodies of a scene whose rigid motions are their own: the one body, or each body of a
// scene of several, with the dof it starts at and the pointer of its supports.
struct BodyPart {
  const Body* body;
  int offset;
  std::string supports;  // the pointer of its supports
  std::string prefix;    // "NAME: " before its motions' names in a scene of several bodies
};

std::vector<BodyPart> body_parts(const Problem& problem) {
  // The BodySet that scene_bodies.cpp built for "bodies": its names and pointers are the scene's.
  const auto* all = dynamic_cast<const BodySet*>(problem.body.get());
  if (!all) return {{problem.body.get(), 0, "/body/supports", ""}};
  std::vector<BodyPart> parts;
  for (int b = 0; b < all->part_count(); ++b)
    parts.push_back(
        {&all->part(b), all->dof_offset(b), "/bodies/" + std::to_string(b) + "/supports", all->name(b) + ": "});
  return parts;
}

// A motion of the whole problem (dofs) in words, per body it moves: "translate along x", or
// "upper: translate along x; lower: translate along x" where it moves several bodies; and the
// first body it moves.
std::pair<std::string, int> motion_words(const std::vector<BodyPart>& parts, const Vector& d) {
  std::string words;
  int first = -1, moved = 0;
  for (size_t b = 0; b < parts.size(); ++b) {
    const Body& body = *parts[b].body;
    const Vector part = d.segment(parts[b].offset, body.dof_count());
    if (part.norm() <= 1e-9 * d.norm()) continue;
    const std::vector<Vector> modes = body_modes(body);
    Matrix B(part.size(), modes.size());
    for (size_t m = 0; m < modes.size(); ++m) B.col(m) = modes[m];
    const Vector c = B.colPivHouseholderQr().solve(part);
    if (first < 0) first = static_cast<int>(b);
    words += (moved++ ? "; " : "") + parts[b].prefix + motion_name(c, body.characteristic_length());
  }
  if (moved == 1 && !parts[first].prefix.empty()) words = words.substr(parts[first].prefix.size());
  return {moved > 1 ? "move together (" + words + ")" : words, std::max(first, 0)};
}

// Free rigid motions are held by contact (docs/algorithm.md#bodies-held-only-by-contact) where the
// model allows it: translations always (internal forces are self-equilibrated at any state),
// rotations where the tangent is constant (linear kinematics: an infinitesimal rotation is a null
// mode of K) or where a finite rotation leaves the body's strain unchanged (the continuum with
// finite kinematics, the von Karman beam, about at most one supported node: its motions then follow
// its state, rigid_modes_at); a membrane (no reference stiffness) never. Records them in
// problem.rigid (pins come later); in a scene of several bodies each body's motions on its own
// dofs.
void check_rigid_modes(Reader& r, Problem& problem) {
  const std::vector<BodyPart> parts = body_parts(problem);
  for (size_t b = 0; b < parts.size(); ++b) {
    const Body& body = *parts[b].body;
    const int o = parts[b].offset, n = body.dof_count();
    std::vector<int> fixed;
    for (const Constraint& c : problem.constraints)
      if (c.dof >= o && c.dof < o + n) fixed.push_back(c.dof - o);
    const double L = body.characteristic_length();
    const std::vector<Vector> free = motion_basis(scene_io::free_motions(body, fixed));
    const std::vector<Vector> modes = body_modes(body);
    for (const Vector& c : free) {
      const bool rotates = c.size() > 2 && std::abs(c[2]) > 1e-9;
      std::string why;
      if (problem.start) why = "a membrane has no stiffness of its own to carry a load to its contacts";
      else if (rotates && !body.traits().constant_tangent) why = finite_rotation_refusal(body, fixed);
      if (!why.empty()) {
        r.error(parts[b].supports, "leave the body free to " + motion_name(c, L) + ": " + why +
                                       "; fix a component that this motion moves, or drive the body by a "
                                       "prescribed displacement");
        continue;
      }
      Vector mode = Vector::Zero(problem.body->dof_count());
      for (int m = 0; m < c.size(); ++m) mode.segment(o, n) += c[m] * modes[m];
      problem.rigid.names.push_back(parts[b].prefix + motion_name(c, L));
      problem.rigid.body.push_back(static_cast<int>(b));
      problem.rigid.modes.conservativeResize(mode.size(), problem.rigid.modes.cols() + 1);
      problem.rigid.modes.col(problem.rigid.modes.cols() - 1) = mode;
    }
  }
}

// With the candidates known: every free motion must move some contact point toward or along
// (with friction) an obstacle or the other body of its pair, else nothing can stop it; and each
// mode gets its pin, a dof that no support and no contact point uses, with the modes
// normalized to 1 at their own pin.
void hold_rigid_modes(Reader& r, Problem& problem) {
  RigidModes& rigid = problem.rigid;
  const Body& body = *problem.body;
  const int count = static_cast<int>(rigid.modes.cols());
  if (count == 0) return;
  const std::vector<BodyPart> parts = body_parts(problem);
  // The contact points in the reference configuration; a pair's Jacobian moves both its bodies.
  const EquilibriumState paired = Equilibrium(problem, NewtonParams{}).evaluate(Vector::Zero(body.dof_count()));
  Matrix G = Matrix::Zero(problem.component_count, count);
  std::vector<char> supported(body.dof_count(), 0), on_contact(body.dof_count(), 0);
  for (const Constraint& c : problem.constraints) supported[c.dof] = 1;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    const PairedPoint& pp = paired.points[i];
    for (const auto& j : pp.point.jacobian) {
      on_contact[j.dof] = 1;
      for (int k = 0; k < count; ++k) {
        G(c.eta, k) += j.dx.dot(pp.eta) * rigid.modes(j.dof, k);
        if (c.xi >= 0) G(c.xi, k) += j.dx.dot(pp.xi) * rigid.modes(j.dof, k);
      }
    }
  }
  const std::string unstoppable =
      ", and no obstacle within reach can stop that motion (no contact point moves toward an obstacle or, with "
      "friction, along it): fix a component that this motion moves, give the obstacle friction, or drive the body "
      "by a prescribed displacement";
  if (problem.candidates.empty()) {
    for (int k = 0; k < count; ++k) {
      const BodyPart& part = parts[rigid.body[k]];
      r.error(part.supports, "leave the body free to " + rigid.names[k].substr(part.prefix.size()) + unstoppable);
    }
    return;
  }
  const Eigen::JacobiSVD<Matrix> svd(G, Eigen::ComputeFullV);
  const double largest = std::max(1.0, svd.singularValues().size() ? svd.singularValues()[0] : 0.0);
  for (int k = 0; k < count; ++k) {
    if (k < svd.singularValues().size() && svd.singularValues()[k] > 1e-6 * largest) continue;
    // The motion that no contact point resists, in words, at the first body it moves.
    const auto [words, b] = motion_words(parts, Vector(rigid.modes * svd.matrixV().col(k)));
    r.error(parts[b].supports, std::string(words.rfind("move together", 0) == 0 ? "leave the bodies free to "
                                                                                : "leave the body free to ") +
                                   words + unstoppable);
  }
  if (!r.issues.empty()) return;
  // Pins: the dofs that pin the modes best (column-pivoted QR of the modes' rows), off the
  // contact points where possible (a beam has none off them; a contact component whose force
  // acts on pins alone still takes part, through the border).
  auto best_pins = [&](bool off_contact) {
    std::vector<int> usable;
    for (int d = 0; d < body.dof_count(); ++d)
      if (!supported[d] && !(off_contact && on_contact[d])) usable.push_back(d);
    Matrix rows(count, usable.size());
    for (size_t a = 0; a < usable.size(); ++a) rows.col(a) = rigid.modes.row(usable[a]).transpose();
    const Eigen::ColPivHouseholderQR<Matrix> qr(rows);
    std::vector<int> pins;
    if (static_cast<int>(usable.size()) >= count && qr.rank() == count)
      for (int k = 0; k < count; ++k) pins.push_back(usable[qr.colsPermutation().indices()[k]]);
    return pins;
  };
  rigid.pins = best_pins(true);
  if (rigid.pins.empty()) rigid.pins = best_pins(false);
  if (rigid.pins.empty()) {
    r.error(parts[rigid.body.front()].supports,
            "leave the body free to " + rigid.names.front() + ", and no free dof can hold it in the solves");
    return;
  }
  Matrix at_pins(count, count);
  for (int k = 0; k < count; ++k) at_pins.row(k) = rigid.modes.row(rigid.pins[k]);
  rigid.modes = (rigid.modes * at_pins.inverse()).eval();
  problem.component_count += count;
}

// `plastic`: a body of the scene yields (its traits' plasticity), which makes cev's real solves
// held by default (docs/algorithm.md#the-held-real-solve).
void read_solver(Reader& r, json& scene, SteppingParams& params, bool plastic) {
  ContactParams& c = params.contact;
  c.real_solve = plastic ? RealSolve::held : RealSolve::given;
  json* solver = r.object(scene, "", "solver", false);
  if (!solver) return;
  const std::string sp = "/solver";
  json* contact = r.object(*solver, sp, "contact", false);
  if (contact) {
    const std::string cp = sp + "/contact";
    const std::string method = r.choice(*contact, cp, "method", {"cev", "uzawa", "penalty", "ssn"}, "cev");
    c.method = method == "uzawa"     ? ContactMethod::uzawa
               : method == "penalty" ? ContactMethod::penalty
               : method == "ssn"     ? ContactMethod::ssn
                                     : ContactMethod::cev;
    if (json* pen = r.object(*contact, cp, "penalty", false)) {
      const std::string pp = cp + "/penalty";
      c.penalty_normal = r.number(*pen, pp, "normal", 0.0);
      c.penalty_tangential = r.number(*pen, pp, "tangential", 0.0);
      c.penalty_factor = r.positive(*pen, pp, "factor", c.penalty_factor);
      if (c.penalty_normal < 0) r.error(pp + "/normal", "is negative");
      if (c.penalty_tangential < 0) r.error(pp + "/tangential", "is negative");
    }
    c.tolerance = r.positive(*contact, cp, "tolerance", c.tolerance);
    if (c.tolerance >= 1) r.error(cp + "/tolerance", "is a relative tolerance and must be below 1");
    const std::string loop = r.choice(*contact, cp, "loop", {"inner", "paper"}, "inner");
    c.loop = loop == "paper" ? ContactLoop::paper : ContactLoop::inner;
    const std::string friction_loop = r.choice(*contact, cp, "friction_loop", {"inner", "passes"}, "inner");
    c.friction_loop = friction_loop == "passes" ? FrictionLoop::passes : FrictionLoop::inner;
    c.real_solve = r.choice(*contact, cp, "real_solve", {"given", "held"}, plastic ? "held" : "given") == "held"
                       ? RealSolve::held
                       : RealSolve::given;
    c.held_stiffness = r.positive(*contact, cp, "held_stiffness", c.held_stiffness);
    c.augmentation = r.positive(*contact, cp, "augmentation", c.augmentation);
    c.max_iterations = r.integer(*contact, cp, "max_iterations", 1, 1000000, c.max_iterations);
    c.max_tau_passes = r.integer(*contact, cp, "max_tau_passes", 1, 1000, c.max_tau_passes);
    c.tau_tolerance = r.positive(*contact, cp, "tau_tolerance", c.tau_tolerance);
    c.uzawa_alpha = r.positive(*contact, cp, "uzawa_alpha", c.uzawa_alpha);
    // 0: the body's characteristic length (written back as 0, meaning "automatic").
    params.contact_reach = r.number(*contact, cp, "reach", 0.0);
    if (params.contact_reach < 0) r.error(cp + "/reach", "is negative");
    params.fail_outside_candidates = r.choice(*contact, cp, "outside_candidates", {"add", "fail"}, "add") == "fail";
    if (json* acc = r.object(*contact, cp, "acceleration", false)) {
      const std::string ap = cp + "/acceleration";
      if (!acc->contains("n")) (*acc)["n"] = "inf";
      const json& n = (*acc)["n"];
      if (n.is_string() && n == "inf") c.acceleration = kAccelerationInfinity;
      else if (n.is_string() && n == "auto") c.acceleration = kAccelerationAuto;
      else if (n.is_number_integer()) c.acceleration = r.integer_value(n, ap + "/n", 1, 64);
      else r.error(ap + "/n", show(n) + " is not \"inf\", \"auto\" or an integer from 1 to 64");
      const std::string eps = r.choice(*acc, ap, "epsilon", {"exact", "warmup"}, "exact");
      c.epsilon = eps == "warmup" ? EpsilonSource::warmup : EpsilonSource::exact;
    }
  }
  if (json* newton = r.object(*solver, sp, "newton", false))
    params.newton.max_iterations =
        r.integer(*newton, sp + "/newton", "max_iterations", 1, 1000, params.newton.max_iterations);
  params.max_cuts = r.integer(*solver, sp, "max_cuts", 0, 30, params.max_cuts);
}

// output: {"steps": "all" | "last" | [step numbers, 1-based], "fields": [...]}.
void read_output(Reader& r, json& scene, Scene& out) {
  json* output = r.object(scene, "", "output", false);
  if (!output) return;
  const size_t n = out.steps.size();
  if (!output->contains("steps")) (*output)["steps"] = "all";
  const json& steps = (*output)["steps"];
  if (steps == "all") {
    out.params.record_fields.clear();
  } else if (steps == "last") {
    out.params.record_fields.assign(n, 0);
    if (n) out.params.record_fields.back() = 1;
  } else if (steps.is_array()) {
    out.params.record_fields.assign(n, 0);
    for (size_t i = 0; i < steps.size(); ++i) {
      const int k =
          r.integer_value(steps[i], "/output/steps/" + std::to_string(i), 1, static_cast<int>(std::max<size_t>(n, 1)));
      if (n) out.params.record_fields[k - 1] = 1;
    }
  } else {
    r.error("/output/steps", show(steps) + " is not \"all\", \"last\" or a list of step numbers");
  }
  if (!output->contains("fields")) (*output)["fields"] = OutputOptions::kAllFields;
  json* fields = r.array(*output, "/output", "fields", false);
  if (!fields) return;
  out.output.fields.clear();
  for (size_t i = 0; i < fields->size(); ++i) {
    const json& f = (*fields)[i];
    if (f.is_string() && std::find(OutputOptions::kAllFields.begin(), OutputOptions::kAllFields.end(),
                                   f.get<std::string>()) != OutputOptions::kAllFields.end())
      out.output.fields.push_back(f.get<std::string>());
    else
      r.error("/output/fields/" + std::to_string(i),
              show(f) + " is not one of " + Reader::list(OutputOptions::kAllFields));
  }
}

// One obstacle motion: a translation at factor 1 of its load case.
void read_motion(Reader& r, json& m, const std::string& ptr, ObstacleInstance& inst) {
  if (!m.is_object()) {
    r.error(ptr, show(m) + " is not an object");
    return;
  }
  const int load_case = r.load_case(m, ptr);
  if (static_cast<int>(inst.translations.size()) <= load_case) inst.translations.resize(load_case + 1, Vec2::Zero());
  inst.translations[load_case] += r.vec2(m, ptr, "translation", Vec2::Zero());
}

// Equal increments of one factor shared by every load case: `steps` as a count or a list.
std::vector<double> read_step_factors(Reader& r, json& scene) {
  if (!scene.contains("steps")) scene["steps"] = 1;
  const json& s = scene["steps"];
  std::vector<double> factors;
  if (s.is_number_integer()) {
    const int n = r.integer_value(s, "/steps", 1, 100000);
    for (int k = 1; k <= n; ++k) factors.push_back(static_cast<double>(k) / n);
  } else if (s.is_array()) {
    if (s.empty() || s.size() > 100000) r.error("/steps", "needs 1 to 100000 load factors");
    for (size_t i = 0; i < s.size(); ++i) {
      if (!s[i].is_number() || !std::isfinite(s[i].get<double>()))
        r.error("/steps/" + std::to_string(i), show(s[i]) + " is not a finite number");
      else factors.push_back(s[i].get<double>());
    }
  } else {
    r.error("/steps", show(s) + " is neither a step count nor a list of load factors");
  }
  return factors;
}

// The load path: without stages every case follows `steps`; with stages each stage ramps the
// factors it names linearly from where the previous stage left them, with its own friction.
// `cases_known`: the bodies and obstacles, which name the load cases, were read without an
// error; otherwise a reader that stopped early (at a bad mesh) may not have met a case a stage
// names, and "names no load case" would be an error of its own making.
std::vector<LoadStep> read_load_path(Reader& r, json& scene, std::vector<ObstacleInstance>& obstacles,
                                     bool cases_known) {
  std::vector<double> base_friction;
  std::unordered_map<std::string, size_t> obstacle_index;
  for (const auto& o : obstacles) {
    obstacle_index.emplace(o.name, base_friction.size());
    base_friction.push_back(o.friction);
  }
  const size_t cases = r.cases.size();
  std::vector<LoadStep> path;
  if (!scene.contains("stages")) {
    for (double f : read_step_factors(r, scene)) path.push_back({LoadFactors(cases, f), base_friction, 0});
    return path;
  }
  if (scene.contains("steps")) r.error("/steps", "cannot be given together with stages (each stage has its steps)");
  json* stages = r.array(scene, "", "stages", true);
  if (!stages) return path;
  if (stages->empty()) r.error("/stages", "needs at least one stage");
  LoadFactors current(cases, 0.0);
  long total = 0;
  for (size_t i = 0; i < stages->size(); ++i) {
    const std::string sp = "/stages/" + std::to_string(i);
    json& st = (*stages)[i];
    if (!st.is_object()) {
      r.error(sp, "is not an object");
      continue;
    }
    const int n = r.integer(st, sp, "steps", 1, 100000);
    LoadFactors target = current;
    if (json* f = r.object(st, sp, "factors", true))
      for (auto& [name, v] : f->items()) {
        const int found = r.find_case(name);
        const size_t k = found < 0 ? cases : static_cast<size_t>(found);
        if (k >= cases) {
          if (cases_known)
            r.error(sp + "/factors/" + token(name), "names no load case (cases: " + Reader::list(r.cases) + ")");
          continue;
        }
        target[k] = r.number(*f, sp + "/factors", name.c_str());
      }
    std::vector<double> friction = base_friction;
    if (json* fr = r.object(st, sp, "friction", false))
      for (auto& [name, v] : fr->items()) {
        const auto named = obstacle_index.find(name);
        const size_t o = named == obstacle_index.end() ? obstacles.size() : named->second;
        if (o == obstacles.size()) {
          r.error(sp + "/friction/" + token(name), "names no obstacle");
          continue;
        }
        friction[o] = r.number(*fr, sp + "/friction", name.c_str());
        if (friction[o] < 0) r.error(sp + "/friction/" + token(name), "is negative");
        if (friction[o] > 0) obstacles[o].frictional = true;
      }
    total += n;
    if (total > 100000) {
      r.error(sp + "/steps", "brings the step count above 100000");
      break;
    }
    for (int k = 1; k <= n; ++k) {
      LoadFactors f(cases);
      for (size_t c = 0; c < cases; ++c) f[c] = current[c] + (target[c] - current[c]) * k / n;
      path.push_back({f, friction, static_cast<int>(i)});
    }
    current = target;
  }
  return path;
}

}  // namespace

SceneErrors::SceneErrors(std::vector<SceneIssue> issues, bool more)
    : std::runtime_error(join(issues)), issues_(std::move(issues)), more_(more) {}

Scene read_scene(const nlohmann::json& input, const MeshResolver& meshes) {
  // Stage 1: the schema (types, ranges, unknown keys); stage 2: the readers' own checks
  // (references, meshes, rigid motions). Both run, so every error is reported at once; a
  // reader error under a value the schema already rejected is left out. The readers run
  // first: a caller may build the schema's validator meanwhile (prepare_schema, grip solve).
  // Each stage lists at most kMaxSceneIssues problems, and so does the whole.
  std::optional<Scene> scene;
  std::vector<SceneIssue> reader_issues;
  bool more = false;
  try {
    scene.emplace(read_checked_scene(input, meshes));
  } catch (const SceneErrors& e) {
    reader_issues = e.issues();
    more = e.more();
  }
  bool schema_more = false;
  std::vector<SceneIssue> schema_issues = validate_against(input, SchemaName::scene, &schema_more);
  if (schema_issues.empty()) {
    if (scene) return std::move(*scene);
    throw SceneErrors(std::move(reader_issues), more);
  }
  more |= schema_more;
  for (const SceneIssue& issue : reader_issues) {
    bool covered = false;
    for (const SceneIssue& s : schema_issues)
      covered |= issue.pointer == s.pointer || issue.pointer.rfind(s.pointer + "/", 0) == 0 || s.pointer == "/";
    if (covered) continue;
    if (schema_issues.size() >= kMaxSceneIssues) {
      more = true;
      break;
    }
    schema_issues.push_back(issue);
  }
  throw SceneErrors(std::move(schema_issues), more);
}

namespace {

// Magnitudes beyond what the arithmetic carries: a modulus or a load of 1e300 overflows the
// products and squared norms of a solve (a diverging Newton then reported a 300-digit
// correction). No quantity of a scene comes near 1e30 in any consistent units.
constexpr double kLargestMagnitude = 1e30;

void refuse_huge_numbers(Reader& r, const json& v, const std::string& pointer) {
  if (v.is_number_float() || v.is_number_integer()) {
    const double x = v.get<double>();
    if (std::abs(x) > kLargestMagnitude)
      r.error(pointer.empty() ? "/" : pointer,
              show(v) + " is beyond " + number_text(kLargestMagnitude) +
                  " in magnitude: the solver's arithmetic would overflow; give the scene in other units");
  } else if (v.is_object()) {
    for (const auto& [key, item] : v.items()) {
      std::string escaped;
      for (const char c : key) escaped += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
      refuse_huge_numbers(r, item, pointer + "/" + escaped);
    }
  } else if (v.is_array()) {
    for (size_t i = 0; i < v.size(); ++i) refuse_huge_numbers(r, v[i], pointer + "/" + std::to_string(i));
  }
}

}  // namespace

Scene read_checked_scene(const nlohmann::json& input, const MeshResolver& meshes) {
  Reader r;
  if (meshes) r.meshes = &meshes;
  Scene scene;
  scene.effective = input;
  json& e = scene.effective;
  if (!e.is_object()) throw SceneErrors(std::vector<SceneIssue>{{"/", "a scene is a JSON object"}});
  refuse_huge_numbers(r, e, "");
  if (!r.issues.empty()) throw SceneErrors(std::move(r.issues));
  const bool several = e.contains("bodies");
  if (several && e.contains("body"))
    r.error("/body", "cannot be given together with bodies (body is the one-body shorthand)");
  if (!several && e.contains("contacts")) r.error("/contacts", "pairs the surfaces of bodies: give bodies, not body");
  if (several) {
    if (json* bodies = r.array(e, "", "bodies", true)) scene_io::read_bodies(r, *bodies, scene.problem);
  } else if (json* body = r.object(e, "", "body", true)) {
    scene_io::read_body(r, *body, scene.problem, "/body");
  }
  json* obs = several && !e.contains("obstacles") ? nullptr : r.array(e, "", "obstacles", !several);
  if (obs) {
    if (obs->empty() && !several) r.error("/obstacles", "needs at least one obstacle");
    std::unordered_set<std::string> obstacle_names;
    for (size_t i = 0; i < obs->size(); ++i) {
      const std::string op = "/obstacles/" + std::to_string(i);
      json& o = (*obs)[i];
      if (!o.is_object()) {
        r.error(op, "is not an object");
        continue;
      }
      ObstacleInstance inst;
      if (!o.contains("name")) o["name"] = "obstacle" + std::to_string(i);
      if (!o["name"].is_string()) r.error(op + "/name", "is not a string");
      else inst.name = o["name"].get<std::string>();
      if (!inst.name.empty() && !obstacle_names.insert(inst.name).second)
        r.error(op + "/name", "\"" + inst.name + "\" names another obstacle already");
      if (json* shape = r.object(o, op, "shape", true)) inst.shape = read_shape(r, *shape, op + "/shape");
      inst.friction = r.number(o, op, "friction", 0.0);
      if (inst.friction < 0) r.error(op + "/friction", show(o["friction"]) + " is negative");
      inst.frictional = inst.friction > 0;
      if (!o.contains("motion")) o["motion"] = json::array();
      if (o["motion"].is_array())
        for (size_t m = 0; m < o["motion"].size(); ++m)
          read_motion(r, o["motion"][m], op + "/motion/" + std::to_string(m), inst);
      else read_motion(r, o["motion"], op + "/motion", inst);
      scene.problem.obstacles.push_back(std::move(inst));
    }
  }
  if (several && r.issues.empty()) scene_io::read_contacts(r, e, scene.problem);
  scene.steps = read_load_path(r, e, scene.problem.obstacles, r.issues.empty());
  scene.load_cases = r.cases;
  scene.problem.case_names = r.cases;
  if (scene.problem.body)
    for (size_t k = 0; k < r.cases.size(); ++k) scene_io::case_load(scene.problem, static_cast<int>(k));
  read_solver(r, e, scene.params, scene.problem.body && scene.problem.body->traits().plasticity);
  read_output(r, e, scene);
  if (r.issues.empty() && scene.problem.body) {
    const auto& recorded = scene.params.record_fields;
    scene.output.quantities =
        scene_io::read_outputs(r, e, scene.problem, std::find(recorded.begin(), recorded.end(), 0) == recorded.end());
  }
  if (r.issues.empty() && scene.problem.body) check_rigid_modes(r, scene.problem);
  if (r.issues.empty()) read_start(r, e, scene.problem);
  if (!r.issues.empty()) throw SceneErrors(std::move(r.issues));
  const double reach =
      scene.params.contact_reach > 0 ? scene.params.contact_reach : scene.problem.body->characteristic_length();
  add_candidates(scene.problem, scene.steps, reach);
  hold_rigid_modes(r, scene.problem);
  // A held body balances its loads on its free motions at the reference (held_by_contact.cpp):
  // a follower load's turn is not in that balance.
  if (r.issues.empty() && scene.problem.rigid.count() > 0 && scene.problem.body->has_follower_loads())
    r.error("/body/loads", "a follower load on a body held only by contact is not supported: support the body");
  if (!r.issues.empty()) throw SceneErrors(std::move(r.issues));
  scene.file_meshes = std::move(r.file_meshes);
  scene.axis_holds = std::move(r.axis_holds);
  return scene;
}

Scene read_scene_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SceneErrors(std::vector<SceneIssue>{{"/", "cannot open " + path}});
  std::ostringstream text;
  text << in.rdbuf();
  if (nested_deeper_than(text.str(), kMaxJsonDepth))
    throw SceneErrors(std::vector<SceneIssue>{{"/", "malformed JSON: arrays and objects are nested deeper than " +
                                                        std::to_string(kMaxJsonDepth) + " levels"}});
  json j;
  try {
    j = json::parse(text.str());
  } catch (const json::exception& e) {  // parse_error, or out_of_range.406 for a number like 1e400
    throw SceneErrors(std::vector<SceneIssue>{{"/", std::string("malformed JSON: ") + e.what()}});
  }
  // body.mesh.gmsh.file: relative to the scene's folder, read once per file.
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  std::map<std::string, std::shared_ptr<const GmshMesh>> read;
  const MeshResolver files = [&](const json& ref) -> std::shared_ptr<const GmshMesh> {
    if (!ref.contains("file") || !ref["file"].is_string())
      throw std::invalid_argument("an uploaded mesh (\"id\") is read by the service; grip solve reads \"file\"");
    const std::string file = (folder / ref["file"].get<std::string>()).string();
    auto& mesh = read[file];
    if (!mesh) mesh = std::make_shared<const GmshMesh>(read_gmsh_file(file));
    return mesh;
  };
  return read_scene(j, files);
}

}  // namespace grip
