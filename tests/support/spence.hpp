#pragma once
// Frictional Hertz (Spence 1975, "The Hertz contact problem with finite friction", J. Elasticity
// 5, 297-319; Johnson, Contact Mechanics, 1985, section 5.4): a rigid cylinder pressed
// monotonically into an elastic half-plane with friction mu. The loading is self-similar, so the
// stick zone |x| < c keeps a fixed ratio c/a, set by beta / mu alone, beta = (1 - 2 nu) /
// (2 (1 - nu)) for an elastic body on a rigid one.
//
// The relation at hand (derived here: Spence's own equation for c/a, and Johnson's figure of
// it, could not be found in the references searched): the load increment of the self-similar
// solution is a flat punch of half-width a that sticks in |x| < c and slips outward beyond,
// q' = mu p' sign x. With the pressure increment taken as the frictionless flat punch's,
// p' ~ 1 / sqrt(a^2 - x^2) (the effect of q on p neglected: first order in beta mu), the stick
// equation beta p' + H[q'] = 0 on |x| < c has a solution bounded at +-c only if
//     beta / mu = K'(c/a) / K(c/a),
// K, K' the complete elliptic integrals of the first kind of modulus c/a and of the
// complementary modulus sqrt(1 - (c/a)^2) (the log-weighted integral of the slip zones'
// Hilbert transform is exactly pi/2 K'; checked numerically). nu = 0.3, mu = 0.3:
// beta / mu = 0.952, c/a = 0.744.
//
// The exact (coupled) problem, the one Spence solved, is computed by the half-plane
// boundary-element model of tests/support/spence_halfplane.hpp: without the coupling it gives
// the relation (stick set 0.750 at a/h 40 and 80, 0.744 at 160), with it c/a = 0.692 at a/h 40
// and 80, 0.684 at 120, 0.680-0.686 at 160 (20 or 40 increments); the peak pressure 8 % over
// Hertz's p0, a 2.5 % short of Hertz's: the coupling lowers c/a by 0.05-0.06. That model, not
// the first-order relation, is what the finite element scene is held to.
#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

// c/a from beta / mu = K'(k) / K(k) (decreasing in k) by bisection.
inline double spence_stick_ratio(double beta_over_mu) {
  auto ratio = [](double k) { return std::comp_ellint_1(std::sqrt(1 - k * k)) / std::comp_ellint_1(k); };
  double lo = 1e-12, hi = 1 - 1e-12;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (ratio(mid) > beta_over_mu ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Spence's setting: an elastic half-plane pressed by a rigid cylinder. A block 2 depth wide
// and depth deep (E = 200 GPa, nu = 0.3, plane strain, q4), its bottom held, under a rigid
// circle R = 100 mm moved down 0.035 mm in `steps` equal steps: a = 1.03 mm at the end, so
// R / a = 100 and, at the default depth of 300 mm, depth / a = 300 (a block 30 mm deep lets
// c/a grow over the loading, 0.71 to 0.76 over steps 6-10: tests/hard/spence_slow_test.cpp;
// 1000 mm deep gives what 300 does). Elements of
// `size` within 1.5 mm of the first touch, growing 1.3-fold from one to the next beyond it.
inline nlohmann::json spence_block(double size, int steps, double mu, double depth = 300) {
  const double extent = 1.5, R = 100;
  auto divisions = [&](double length) {
    int n = static_cast<int>(std::lround(extent / size));
    for (double h = size, covered = extent; covered < length; covered += h *= 1.3) ++n;
    return n;
  };
  nlohmann::json j = nlohmann::json::parse(R"({
    "name": "spence-block", "units": {"force": "N", "length": "mm"},
    "body": {"model": "continuum", "kinematics": "linear", "analysis": "plane_strain", "element": "q4",
             "thickness": 1, "material": {"young": 200000, "poisson": 0.3}, "contact_set": "top",
             "supports": [{"set": "bottom", "fix": ["x", "y"]}]},
    "obstacles": [{"name": "cylinder", "shape": {"type": "circle"}, "motion": {"translation": [0, -0.035]}}],
    "solver": {"contact": {"method": "cev", "tolerance": 1e-8}}})");
  j["body"]["mesh"]["rectangle"] = {{"origin", {-depth, -depth}},
                                    {"size", {2 * depth, depth}},
                                    {"divisions", {2 * divisions(depth), divisions(depth)}},
                                    {"refine", {{"towards", {0, 0}}, {"size", size}, {"extent", extent}}}};
  j["obstacles"][0]["shape"]["centre"] = {0, R};
  j["obstacles"][0]["shape"]["radius"] = R;
  j["obstacles"][0]["friction"] = mu;
  j["steps"] = steps;
  return j;
}

// The shipped Hertz geometry (R = 10 mm, E = 200 GPa, nu = 0.3, plane strain, q4) with
// elements of `size` near the pole, friction mu, the diameter held in y only and its centre in
// x, `steps` equal steps of the diameter's displacement (0.05 mm): a finite cylinder (R / a =
// 20), whose surface stretch raises c/a over the half-plane's (README, frictional Hertz).
inline nlohmann::json frictional_hertz(double size, int steps, double mu) {
  nlohmann::json j = with_pole_elements(example_scene("hertz"), size);
  j["obstacles"][0]["friction"] = mu;
  j["body"]["supports"] = nlohmann::json::parse(
      R"([{"set": "diameter", "fix": ["y"], "values": {"y": -0.05}}, {"set": "centre", "fix": ["x"]}])");
  j["steps"] = steps;
  return j;
}

struct SpenceReading {
  bool found = false;
  double a = 0;        // contact half-width: where the pressure's square, extrapolated, vanishes
  double c = 0;        // stick half-width by the solver's states, midway between the last
                       // sticking node and the next (the half-plane model's stick set)
  double c_rule = 0;   // the same by the rule |sigma_t| < 0.99 mu |sigma_n|
  HertzContact hertz;  // the frictionless closed form at the computed load
  double peak = 0;     // largest nodal pressure over Hertz's p0
};

// The stick zone is the run of sticking nodes from the centre. The cylinder is the rigid circle
// pressing the body, or else the body's half-disc.
inline SpenceReading read_spence(const Solved& s, const StepRecord& rec, double mu) {
  const nlohmann::json& body = s.scene.effective["body"];
  const nlohmann::json& shape = s.scene.effective["obstacles"][0]["shape"];
  const double radius = shape["type"] == "circle" ? shape["radius"].get<double>() : 0.0;
  SpenceReading r;
  r.hertz = hertz_contact(
      body, std::abs(reaction_resultant(s.scene.problem, rec).y()) / body["thickness"].get<double>(), radius);
  const auto nodes = contact_profile(s.scene.problem, rec);
  const Zone contact = contact_zone(nodes);
  if (!contact.found) return r;
  r.a = contact.half_width();
  for (const auto& n : nodes) r.peak = std::max(r.peak, -n.sigma_n / r.hertz.p0);
  const int count = static_cast<int>(nodes.size());
  int centre = 0;
  for (int k = 0; k < count; ++k)
    if (std::abs(nodes[k].x) < std::abs(nodes[centre].x)) centre = k;
  auto half_width = [&](auto sticks) {  // 0 when no node sticks or all do
    int hi = centre, lo = centre;
    while (hi + 1 < count && sticks(nodes[hi + 1])) ++hi;
    while (lo > 0 && sticks(nodes[lo - 1])) --lo;
    if (!sticks(nodes[centre]) || hi + 1 >= count || lo < 1) return 0.0;
    return 0.25 * ((nodes[hi].x + nodes[hi + 1].x) - (nodes[lo].x + nodes[lo - 1].x));
  };
  r.c = half_width([](const ContactNode& n) { return n.state == ContactState::stick; });
  r.c_rule = half_width([mu](const ContactNode& n) { return std::abs(n.sigma_t) < 0.99 * mu * std::abs(n.sigma_n); });
  r.found = true;
  return r;
}

}  // namespace grip::testing
