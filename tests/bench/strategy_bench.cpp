// grip_bench: what accuracy costs. For every example scene x mesh level x contact strategy x
// tolerance, the median wall time of repeated runs, the work counters (contact iterations =
// real equilibrium solves, Newton iterations, factorizations), the error of the answer
// against a reference (a closed form where one exists, else the finest mesh at the tightest
// tolerance), and the overhead ratio: the time of the contact solves over the time of one
// equilibrium solve per step with the converged contact forces given as known loads (the
// floor that no contact method can beat). Writes one CSV row per combination.
//
// Numbers are reported, never asserted: the targets of the issue are printed as met or not.
//
//   grip_bench [--quick] [--out DIR] [--runs N] [--jobs N] [--budget MINUTES]
//              [--run-seconds S] [--scenes a,b] [--strategies a,b] [--levels 0,1,2] [--source DIR]
//              [--label TEXT]
#include <malloc.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <time.h>

#include <nlohmann/json.hpp>

#include "solver/equilibrium/equilibrium.hpp"
#include "solver/io/scene.hpp"
#include "solver/stepping/load_stepping.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/elastica.hpp"

#ifndef GRIP_SOURCE_DIR
#define GRIP_SOURCE_DIR "."
#endif

namespace grip::bench {
namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;
using testing::contact_resultant;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// CPU time of the calling thread: less sensitive than wall time to other work on the machine.
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// ---------------------------------------------------------------------------------------------
// What is measured on a solved scene. Four slots; each scene says what its slots mean.

struct Quantities {
  double force = kNaN;   // a total contact force
  double peak = kNaN;    // a peak value: contact stress, or strain
  double point = kNaN;   // a displacement at a named point
  double extent = kNaN;  // the contact half-width (closed-form scenes)
};

std::vector<double> column(const FieldTable& t, const std::string& name) {
  const auto it = std::find(t.names.begin(), t.names.end(), name);
  if (it == t.names.end()) throw std::runtime_error("no field \"" + name + "\"");
  const size_t c = static_cast<size_t>(it - t.names.begin());
  std::vector<double> out;
  for (const auto& row : t.rows) out.push_back(row.at(c));
  return out;
}

// The largest normal contact stress |p_n| / tributary area.
double peak_normal_stress(const Problem& problem, const StepRecord& rec) {
  double peak = 0.0;
  for (const Candidate& c : problem.candidates)
    peak = std::max(peak, std::abs(rec.p[c.eta]) / problem.body->tributary_area(c.site));
  return peak;
}

// ---------------------------------------------------------------------------------------------
// Scenes.

struct SceneCase {
  std::string name;                                // short name used in the CSV and the plots
  std::string file;                                // schemas/examples/<file>.json
  std::function<json(json, int level)> with_mesh;  // level 0, 1, 2: coarse to fine
  std::function<std::string(const json&)> mesh_label;
  std::function<Quantities(const Scene&, const RunResult&)> measure;
  // The closed-form values of the measured run where there are some (NaN elsewhere); the
  // other quantities are compared with the finest mesh at the tightest tolerance.
  std::function<Quantities(const Scene&, const RunResult&)> closed_form;
  std::string quantities;        // what force / peak / point / extent mean, for the report
  std::string closed_form_note;  // which quantities have a closed form, and which
};

// The continuum scenes (a half-disc refined near its pole) set the element size near the
// contact, with the fewest divisions beyond the refined zone that the generator accepts.
json with_pole_size(json j, double size) { return testing::with_pole_elements(std::move(j), size); }

std::string half_disc_label(const json& j) {
  const json& disc = j["body"]["mesh"]["half_disc"];
  std::ostringstream s;
  s << "h" << disc["refine"]["size"].get<double>() << " (" << disc["divisions"][0].get<int>() << "x"
    << disc["divisions"][1].get<int>() << ")";
  return s.str();
}

// A displacement component at the reference point (0, y) on the half-disc's axis, interpolated
// linearly between the axis nodes: a field value that every mesh level can be read at.
double axis_displacement(const Problem& problem, const StepRecord& rec, double y, const std::string& component) {
  const auto x = column(rec.site_fields, "x"), yy = column(rec.site_fields, "y");
  const auto ux = column(rec.site_fields, "ux"), uy = column(rec.site_fields, "uy");
  const auto& u = component == "ux" ? ux : uy;
  std::vector<std::pair<double, double>> axis;  // (reference y, displacement)
  const double length = problem.body->characteristic_length();
  for (size_t n = 0; n < x.size(); ++n)
    if (std::abs(x[n] - ux[n]) < 1e-9 * length) axis.emplace_back(yy[n] - uy[n], u[n]);
  std::sort(axis.begin(), axis.end());
  for (size_t k = 1; k < axis.size(); ++k)
    if (axis[k - 1].first <= y && y <= axis[k].first) {
      const double t = (y - axis[k - 1].first) / (axis[k].first - axis[k - 1].first);
      return (1 - t) * axis[k - 1].second + t * axis[k].second;
    }
  return kNaN;
}

// P (normal) and Q (tangential) per unit thickness from the support reactions, and Hertz's
// a and p0 at that P.
struct HalfDiscLoad {
  double Q = 0.0;
  testing::HertzContact hertz;
};
HalfDiscLoad half_disc_load(const Scene& sc, const StepRecord& rec) {
  const json& body = sc.effective["body"];
  const double t = body["thickness"];
  const Vec2 reaction = testing::reaction_resultant(sc.problem, rec);
  return {std::abs(reaction.x()) / t, testing::hertz_contact(body, -reaction.y() / t)};
}

// Hertz (frictionless) and Cattaneo-Mindlin (then sheared) on the half-disc: peak nodal normal
// stress against Hertz's p0 and a zone half-width (contact, or stick) against its closed form,
// both at the run's own load; the load and a displacement on the axis at half the radius below
// the centre against the finest mesh.
SceneCase half_disc_case(bool sheared, std::array<double, 3> sizes) {
  SceneCase s;
  s.name = sheared ? "cattaneo-mindlin" : "hertz";
  s.file = s.name;
  s.with_mesh = [sizes](json j, int level) { return with_pole_size(std::move(j), sizes[level]); };
  s.mesh_label = half_disc_label;
  s.measure = [sheared](const Scene& sc, const RunResult& run) {
    const StepRecord& last = run.steps.back();
    const auto nodes = testing::contact_profile(sc.problem, last);
    const HalfDiscLoad load = half_disc_load(sc, last);
    const double radius = sc.effective["body"]["mesh"]["half_disc"]["radius"];
    Quantities q;
    q.peak = 0.0;
    for (const auto& n : nodes) q.peak = std::max(q.peak, -n.sigma_n);
    q.force = sheared ? load.Q : load.hertz.P;
    q.point = axis_displacement(sc.problem, last, -0.5 * radius, sheared ? "ux" : "uy");
    if (sheared) {
      const testing::Zone stick = testing::stick_zone(nodes, sc.problem.obstacles[0].friction);
      q.extent = stick.found ? stick.half_width() : kNaN;
    } else {
      const testing::EllipseFit fit = testing::fit_semi_ellipse(nodes);
      q.extent = fit.a > 0 ? fit.a : kNaN;
    }
    return q;
  };
  s.closed_form = [sheared](const Scene& sc, const RunResult& run) {
    const HalfDiscLoad load = half_disc_load(sc, run.steps.back());
    const double mu = sc.problem.obstacles[0].friction;
    Quantities q;
    q.peak = load.hertz.p0;
    q.extent = sheared ? load.hertz.a * std::sqrt(std::max(0.0, 1 - load.Q / (mu * load.hertz.P))) : load.hertz.a;
    return q;
  };
  const std::string load = sheared ? "force: tangential load Q" : "force: load P";
  s.quantities = load +
                 " per unit thickness from the reactions (N/mm); peak: peak nodal normal contact stress "
                 "(MPa); point: " +
                 (sheared ? "tangential" : "vertical") +
                 " displacement on the axis at half the radius below the centre (mm); extent: " +
                 (sheared ? "stick-zone half-width c (mm)"
                          : "contact half-width a from the semi-ellipse fitted to the nodal stresses (mm)");
  s.closed_form_note = sheared ? "closed form for peak (Hertz p0 at the run's own P) and extent (c = a sqrt(1 - "
                                 "Q/(mu P))); force and point against the finest mesh"
                               : "closed form for peak (p0 = 2P/(pi a)) and extent (a = sqrt(4PR/(pi E*))) at the "
                                 "run's own P; force and point against the finest mesh";
  return s;
}

// The slender strip of issue 13 (L/t = 50, q9, finite strain, F L^2/EI = 10): free, where the
// tip deflection has the elastica's closed form, or wrapped onto a cylinder with friction.
SceneCase strip_case(const std::string& name, const std::string& file) {
  SceneCase s;
  s.name = name;
  s.file = file;
  s.with_mesh = [](json j, int level) {
    j["body"]["mesh"]["rectangle"]["divisions"][0] = 25 << level;
    return j;
  };
  s.mesh_label = [](const json& j) {
    const json& d = j["body"]["mesh"]["rectangle"]["divisions"];
    return std::to_string(d[0].get<int>()) + "x" + std::to_string(d[1].get<int>());
  };
  // The free end's mid-surface node (largest reference x, reference y nearest t/2 = 0.01).
  auto tip = [](const StepRecord& last, const std::string& component) {
    const auto x = column(last.site_fields, "x"), ux = column(last.site_fields, "ux");
    const auto y = column(last.site_fields, "y"), uy = column(last.site_fields, "uy");
    const auto c = column(last.site_fields, component);
    size_t end = 0;
    auto distance = [&](size_t n) { return std::hypot(x[n] - ux[n] - 1.0, y[n] - uy[n] - 0.01); };
    for (size_t n = 0; n < x.size(); ++n)
      if (distance(n) < distance(end)) end = n;
    return c[end];
  };
  s.measure = [tip](const Scene& sc, const RunResult& run) {
    const StepRecord& last = run.steps.back();
    Quantities q;
    q.force = contact_resultant(sc.problem, last).norm();
    q.peak = peak_normal_stress(sc.problem, last);
    q.point = -tip(last, "uy");
    return q;
  };
  if (name == "cantilever")
    s.closed_form = [](const Scene&, const RunResult&) {
      Quantities q;
      q.point = testing::elastica_tip(10.0).deflection;  // L = 1
      return q;
    };
  s.quantities = "force: total contact force; peak: peak normal contact stress; point: tip deflection (mid-surface)";
  s.closed_form_note = name == "cantilever" ? "closed form for point (the elastica's tip deflection, Mattiasson 1981)"
                                            : "every quantity against the finest mesh";
  return s;
}

std::vector<SceneCase> scene_cases() {
  std::vector<SceneCase> out;
  {
    SceneCase s;
    s.name = "beam";
    s.file = "beam-on-cylinder";
    s.mesh_label = [](const json& j) { return std::to_string(j["body"]["mesh"]["elements"].get<int>()); };
    s.with_mesh = [](json j, int level) {
      const int n = 20 << level;
      j["body"]["mesh"]["elements"] = n;
      j["body"]["loads"][0]["node"] = n;
      return j;
    };
    s.measure = [](const Scene& sc, const RunResult& run) {
      const StepRecord& last = run.steps.back();
      Quantities q;
      q.force = contact_resultant(sc.problem, last).norm();
      q.peak = peak_normal_stress(sc.problem, last);
      q.point = -column(last.site_fields, "w").back();  // tip deflection at the end node
      return q;
    };
    s.quantities =
        "force: total contact force (kgf); peak: peak normal contact stress (kgf/cm2); "
        "point: tip deflection at the end node (cm)";
    out.push_back(std::move(s));
  }
  {
    SceneCase s;
    s.name = "sheet";
    s.file = "sheet-stretching";
    s.mesh_label = [](const json& j) { return std::to_string(j["body"]["mesh"]["elements"].get<int>()); };
    s.with_mesh = [](json j, int level) {
      const int n = 30 << level;
      j["body"]["mesh"]["elements"] = n;
      j["body"]["supports"][1]["node"] = n;
      return j;
    };
    s.measure = [](const Scene& sc, const RunResult& run) {
      const StepRecord& last = run.steps.back();
      Quantities q;
      const auto named = std::find_if(sc.problem.obstacles.begin(), sc.problem.obstacles.end(),
                                      [](const ObstacleInstance& o) { return o.name == "punch"; });
      const int punch = static_cast<int>(named - sc.problem.obstacles.begin());
      q.force = -contact_resultant(sc.problem, last, punch).y();  // the punch force
      const auto strain = column(last.element_fields, "major_strain");
      q.peak = *std::max_element(strain.begin(), strain.end());
      q.point = -column(last.site_fields, "uy").front();  // the pole's displacement
      return q;
    };
    s.quantities =
        "force: punch force (N per mm width); peak: peak major strain; "
        "point: pole displacement (mm)";
    out.push_back(std::move(s));
  }
  out.push_back(half_disc_case(false, {0.1, 0.05, 0.025}));  // 0.05 as shipped
  // 0.028 as shipped; below 0.02 the generator makes inverted elements at this grading.
  out.push_back(half_disc_case(true, {0.056, 0.028, 0.02}));
  out.push_back(strip_case("cantilever", "strip-cantilever"));
  out.push_back(strip_case("strip-cylinder", "strip-on-cylinder"));
  {
    // The block pressed and slid on a flat (20 x 10 elements as shipped).
    SceneCase s;
    s.name = "sliding-block";
    s.file = "sliding-block";
    s.mesh_label = [](const json& j) {
      const json& d = j["body"]["mesh"]["rectangle"]["divisions"];
      return std::to_string(d[0].get<int>()) + "x" + std::to_string(d[1].get<int>());
    };
    s.with_mesh = [](json j, int level) {
      j["body"]["mesh"]["rectangle"]["divisions"] = {10 << level, 5 << level};
      return j;
    };
    s.measure = [](const Scene& sc, const RunResult& run) {
      const StepRecord& last = run.steps.back();
      Quantities q;
      const Vec2 reaction = testing::reaction_resultant(sc.problem, last);
      q.force = std::abs(reaction.x());  // Q, mu N once every node slips
      q.peak = peak_normal_stress(sc.problem, last);
      return q;
    };
    s.quantities = "force: tangential reaction Q (N per mm); peak: peak normal contact stress (MPa)";
    out.push_back(std::move(s));
  }
  // Frictionless twins of the scenes with friction (issue 15: each strategy with and without).
  for (const char* name : {"beam", "sheet", "sliding-block"}) {
    SceneCase s = *std::find_if(out.begin(), out.end(), [&](const SceneCase& c) { return c.name == name; });
    s.name += "-mu0";
    s.with_mesh = [mesh = s.with_mesh](json j, int level) {
      for (json& o : j["obstacles"]) o["friction"] = 0.0;
      return mesh(std::move(j), level);
    };
    out.push_back(std::move(s));
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Strategies.

struct Strategy {
  std::string name;
  json contact;        // solver.contact of the scene
  int max_cuts = -1;   // solver.max_cuts; -1: the scene's default
  std::string family;  // cev, ssn, cev-inner (tau passes), cev-paper, uzawa, penalty (for the plots)
};

// Real solves per load step for the loops that are known to stall (the paper's literal loop
// and uzawa, docs/algorithm.md#reading-the-paper): they stop there, recorded as not reaching the
// tolerance, and their increments are not cut.
constexpr int kCappedIterations = 300;

std::vector<Strategy> strategies(bool quick) {
  std::vector<Strategy> out;
  auto cev = [&](const std::string& n_text, const json& n, const std::string& eps, bool paper) {
    Strategy s;
    s.name = "cev-" + n_text + (eps.empty() ? "" : "-" + eps) + (paper ? "-paper" : "");
    // The acceleration level n matters with the tau passes (inner loop by eq. 13) and in the
    // paper's loop; cev's default (the bound moving with p) does not use it.
    s.contact = {{"method", "cev"}, {"loop", paper ? "paper" : "inner"}, {"friction_loop", "passes"}};
    s.contact["acceleration"] = {{"n", n}};
    if (!eps.empty()) s.contact["acceleration"]["epsilon"] = eps;
    if (paper) {
      s.contact["max_iterations"] = kCappedIterations;
      s.max_cuts = 0;
    }
    s.family = paper ? "cev-paper" : "cev-inner";
    out.push_back(s);
  };
  auto newton_like = [&](const std::string& method) {  // cev's default, ssn
    Strategy s;
    s.name = method;
    s.contact = {{"method", method}};
    s.family = method;
    out.push_back(s);
  };
  auto uzawa = [&] {
    Strategy s;
    s.name = "uzawa";
    s.contact = {{"method", "uzawa"}, {"max_iterations", kCappedIterations}};
    s.max_cuts = 0;
    s.family = "uzawa";
    out.push_back(s);
  };
  auto penalty = [&](double factor) {
    Strategy s;
    std::ostringstream name;
    name << "penalty-k" << factor;
    s.name = name.str();
    s.contact = {{"method", "penalty"}, {"penalty", {{"factor", factor}}}};
    s.family = "penalty";
    out.push_back(s);
  };
  newton_like("cev");
  newton_like("ssn");
  if (quick) {
    cev("inf", "inf", "", false);
    cev("auto", "auto", "exact", false);
    cev("8", 8, "exact", true);
    uzawa();
    penalty(1e3);
    return out;
  }
  for (bool paper : {false, true}) {
    cev("inf", "inf", "", paper);
    for (const char* eps : {"exact", "warmup"}) {
      cev("auto", "auto", eps, paper);
      for (int n : {2, 4, 8, 12, 16}) cev(std::to_string(n), n, eps, paper);
    }
  }
  uzawa();
  for (double factor : {1e0, 1e1, 1e2, 1e3, 1e4}) penalty(factor);
  return out;
}

// ---------------------------------------------------------------------------------------------
// One run, and the overhead replay.

struct RunStats {
  // ok: every step converged with ||v|| within the tolerance; not reached: every step ended
  // but ||v|| stayed above it (penalty has no loop); limit: a step used up its contact
  // iterations; failed: any other failure (the reason says which); timeout: the run's wall
  // time ran out; skipped: not run.
  std::string status;
  std::string reason;
  double seconds = kNaN;      // wall time of run_load_steps
  double cpu_seconds = kNaN;  // the thread's CPU time over the same call
  long solves = 0, newton = 0, factorizations = 0, inner = 0, passes = 0, cuts = 0;
  double max_v_rel = 0.0;  // the largest final ||v||_2 of a step, relative to the body's length
  Quantities q;
  std::vector<int> step_solves;   // contact iterations of each step that ended
  std::vector<StepRecord> steps;  // for the replay
};

RunStats run_once(const SceneCase& sc, const json& scene_json, double wall_limit) {
  Scene scene = read_scene(scene_json);
  SteppingObserver obs;
  const auto t0 = Clock::now();
  bool timed_out = false;
  obs.stop_requested = [&] { return timed_out = seconds_since(t0) > wall_limit; };
  const double cpu0 = thread_cpu_seconds();
  RunResult run = run_load_steps(scene.problem, scene.steps, scene.params, obs);
  RunStats st;
  st.cpu_seconds = thread_cpu_seconds() - cpu0;
  st.seconds = run.seconds;
  st.solves = run.counters.solves;
  st.newton = run.counters.newton_iterations;
  st.factorizations = run.counters.factorizations;
  const double length = scene.problem.body->characteristic_length();
  for (const StepRecord& rec : run.steps) {
    st.inner += rec.inner_iterations;
    st.passes += rec.passes;
    st.cuts += rec.cuts;
    if (!rec.history.empty()) st.max_v_rel = std::max(st.max_v_rel, rec.history.back().v2 / length);
    st.step_solves.push_back(rec.solves);
  }
  if (!run.completed) {
    const bool limit = run.reason.find(" contact iterations") != std::string::npos;
    st.status = timed_out ? "timeout" : limit ? "limit" : "failed";
    st.reason = timed_out ? "stopped after the wall-time limit of " + std::to_string(wall_limit) + " s: " + run.reason
                          : run.reason;
    return st;
  }
  st.q = sc.measure(scene, run);
  const double tol = scene.params.contact.tolerance;
  if (st.max_v_rel > tol * (1 + 1e-9)) {
    st.status = "not reached";
    st.reason = "contact error " + std::to_string(st.max_v_rel) + " above the tolerance (penalty has no loop)";
  } else {
    st.status = "ok";
  }
  st.steps = std::move(run.steps);
  return st;
}

// The floor: for every converged step, one equilibrium solve with the converged contact forces
// given, from the same displacement guess the load stepping made (the previous step's
// increment, extrapolated), with the body's history and pairing committed as in the run. The
// first step of a body with a start-up solve is left out (its guess comes from that solve),
// from both sums. Returns (contact seconds, equilibrium seconds), summed over the steps.
std::pair<double, double> overhead(const json& scene_json, const RunStats& st, int repeats) {
  std::vector<double> floors;
  double contact = 0.0;
  for (int r = 0; r < repeats; ++r) {
    Scene scene = read_scene(scene_json);
    Problem& problem = scene.problem;
    Equilibrium eq(problem, scene.params.newton);
    couple_newton(eq.params(), scene.params.contact.tolerance, scene.params.contact.newton_fraction,
                  problem.body->characteristic_length());
    const int ndof = problem.body->dof_count();
    const size_t cases = scene.steps.empty() ? 1 : scene.steps.front().factors.size();
    Vector q = Vector::Zero(ndof), q_before = q;
    LoadFactors current(cases, 0.0), before = current;
    eq.set_step(current, std::vector<double>(problem.candidates.size(), 0.0));
    std::vector<double> zeta = eq.zetas(eq.evaluate(q));
    auto distance = [](const LoadFactors& a, const LoadFactors& b) {
      double d = 0.0;
      for (size_t k = 0; k < a.size() && k < b.size(); ++k) d += (a[k] - b[k]) * (a[k] - b[k]);
      return std::sqrt(d);
    };
    double floor = 0.0;
    contact = 0.0;
    for (size_t k = 0; k < st.steps.size(); ++k) {
      const StepRecord& rec = st.steps[k];
      for (size_t o = 0; o < scene.steps[k].friction.size() && o < problem.obstacles.size(); ++o)
        problem.obstacles[o].friction = scene.steps[k].friction[o];
      eq.set_step(rec.factors, zeta);
      if (!(k == 0 && problem.start)) {
        const double last = distance(current, before);
        const Vector guess = last > 0 ? Vector(q + (q - q_before) * (distance(rec.factors, current) / last)) : q;
        const auto t0 = Clock::now();
        const EquilibriumState s = eq.solve(guess, rec.p);
        floor += seconds_since(t0);
        contact += rec.seconds;
        (void)s;
      }
      problem.body->commit(rec.state.q);
      q_before = q;
      q = rec.state.q;
      before = current;
      current = rec.factors;
      zeta = eq.zetas(rec.state);
    }
    floors.push_back(floor);
  }
  return {contact, median(floors)};
}

// ---------------------------------------------------------------------------------------------
// The matrix.

struct Row {
  std::string scene, mesh, strategy, family;
  int level = 0;
  double tolerance = 0.0;
  int runs = 0;
  RunStats stats;  // of the median run (counters and quantities are the same in every run)
  double median_seconds = kNaN, min_seconds = kNaN, median_cpu_seconds = kNaN;
  Quantities error;
  double contact_seconds = kNaN, floor_seconds = kNaN, overhead_ratio = kNaN;
};

double relative_error(double value, double reference) {
  if (!std::isfinite(value) || !std::isfinite(reference) || reference == 0.0) return kNaN;
  return std::abs(value - reference) / std::abs(reference);
}

Quantities errors(const Quantities& q, const Quantities& ref) {
  return {relative_error(q.force, ref.force), relative_error(q.peak, ref.peak), relative_error(q.point, ref.point),
          relative_error(q.extent, ref.extent)};
}

std::string csv_number(double v) {
  if (!std::isfinite(v)) return "";
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string csv_text(std::string s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c == '\n' ? ' ' : c;
  }
  return out + "\"";
}

std::string join(const std::vector<int>& v) {
  std::ostringstream out;
  for (size_t i = 0; i < v.size(); ++i) out << (i ? ";" : "") << v[i];
  return out.str();
}

void write_csv(const std::filesystem::path& path, std::vector<Row> rows) {
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    return std::tie(a.scene, a.level, a.strategy, b.tolerance) < std::tie(b.scene, b.level, b.strategy, a.tolerance);
  });
  std::ofstream out(path);
  out << "scene,mesh,mesh_level,strategy,family,tolerance,runs,median_seconds,min_seconds,median_cpu_seconds,"
         "status,converged,"
         "contact_iterations,inner_iterations,tau_passes,cuts,newton_iterations,factorizations,max_contact_error,"
         "force,peak,point,extent,err_force,err_peak,err_point,err_extent,contact_seconds,equilibrium_seconds,"
         "overhead_ratio,step_solves,reason\n";
  for (const Row& r : rows) {
    const RunStats& s = r.stats;
    out << r.scene << ',' << r.mesh << ',' << r.level << ',' << r.strategy << ',' << r.family << ','
        << csv_number(r.tolerance) << ',' << r.runs << ',' << csv_number(r.median_seconds) << ','
        << csv_number(r.min_seconds) << ',' << csv_number(r.median_cpu_seconds) << ',' << s.status << ','
        << (s.status == "ok" ? 1 : 0) << ',' << s.solves << ',' << s.inner << ',' << s.passes << ',' << s.cuts << ','
        << s.newton << ',' << s.factorizations << ',' << csv_number(s.max_v_rel) << ',' << csv_number(s.q.force) << ','
        << csv_number(s.q.peak) << ',' << csv_number(s.q.point) << ',' << csv_number(s.q.extent) << ','
        << csv_number(r.error.force) << ',' << csv_number(r.error.peak) << ',' << csv_number(r.error.point) << ','
        << csv_number(r.error.extent) << ',' << csv_number(r.contact_seconds) << ',' << csv_number(r.floor_seconds)
        << ',' << csv_number(r.overhead_ratio) << ',' << join(s.step_solves) << ',' << csv_text(s.reason) << '\n';
  }
}

struct Options {
  bool quick = false;
  std::filesystem::path out = "bench/results";
  std::filesystem::path source = GRIP_SOURCE_DIR;
  int runs = 5;
  int jobs = 1;
  double budget_minutes = 40.0;
  double run_seconds = 3.0;  // wall-time limit of one run
  std::string label;         // what was measured (a commit), for machine.txt
  std::vector<std::string> scenes;
  std::vector<std::string> strategies;  // names to run; empty: all
  std::vector<int> levels;              // mesh levels to run (0 coarse .. 2 fine); empty: all
};

struct Task {
  const SceneCase* scene;
  int level;
  const Strategy* strategy;
};

class Bench {
 public:
  explicit Bench(Options opt) : opt_(std::move(opt)), start_(Clock::now()), load_at_start_(load_average()) {}

  int run() {
    std::filesystem::create_directories(opt_.out);
    tolerances_ = opt_.quick ? std::vector<double>{1e-4, 1e-8} : std::vector<double>{1e-2, 1e-4, 1e-6, 1e-8, 1e-10};
    levels_ = opt_.quick ? std::vector<int>{0} : std::vector<int>{0, 1, 2};
    if (!opt_.levels.empty()) levels_ = opt_.levels;
    const auto all_strategies = strategies(opt_.quick);
    for (const SceneCase& sc : scene_cases()) {
      if (!opt_.scenes.empty() && std::find(opt_.scenes.begin(), opt_.scenes.end(), sc.name) == opt_.scenes.end())
        continue;
      const auto path = opt_.source / "schemas/examples" / (sc.file + ".json");
      if (!std::filesystem::exists(path)) {
        std::printf("note: scene %s (%s) is not in this checkout: skipped\n", sc.name.c_str(), path.c_str());
        continue;
      }
      std::ifstream in(path);
      base_[sc.name] = json::parse(in);
      cases_.push_back(sc);
    }
    for (const SceneCase& sc : cases_) reference(sc);
    for (const SceneCase& sc : cases_)
      for (int level : levels_) calibrate(sc, level);
    // The middle mesh first: the table and the plots read it, so a spent budget leaves holes
    // only on the other meshes.
    std::vector<int> order = levels_;
    std::stable_sort(order.begin(), order.end(), [](int a, int b) { return (a == 1) > (b == 1); });
    std::vector<Task> tasks;
    for (int level : order)
      for (const SceneCase& sc : cases_)
        for (const Strategy& st : all_strategies)
          if (opt_.strategies.empty() ||
              std::find(opt_.strategies.begin(), opt_.strategies.end(), st.name) != opt_.strategies.end())
            tasks.push_back({&sc, level, &st});
    std::printf("%zu scene x mesh x strategy combinations, %zu tolerances each, %d runs, %d worker(s)\n", tasks.size(),
                tolerances_.size(), opt_.runs, opt_.jobs);
    std::atomic<size_t> next{0};
    auto worker = [&] {
      for (size_t i = next++; i < tasks.size(); i = next++) measure(tasks[i], i, tasks.size());
    };
    std::vector<std::thread> pool;
    for (int w = 1; w < opt_.jobs; ++w) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
    write_csv(opt_.out / "strategies.csv", rows_);
    write_scenes();
    write_machine();
    std::printf("wrote %s (%zu rows) after %.0f s\n", (opt_.out / "strategies.csv").c_str(), rows_.size(),
                seconds_since(start_));
    report_targets();
    return 0;
  }

 private:
  std::string label(const SceneCase& sc, int level) const {
    return sc.mesh_label(sc.with_mesh(base_.at(sc.name), level));
  }

  json scene_json(const SceneCase& sc, int level, const Strategy& st, double tol) const {
    json j = sc.with_mesh(base_.at(sc.name), level);
    json contact = st.contact;
    contact["tolerance"] = tol;
    j["solver"]["contact"] = contact;
    if (st.max_cuts >= 0) j["solver"]["max_cuts"] = st.max_cuts;
    j["output"] = {{"steps", "last"}};
    return j;
  }

  // The reference answer: the finest mesh at the tightest tolerance, with the default strategy
  // (cev, n = inf, inner loop), a looser tolerance if that one fails; a scene's closed forms
  // replace it for the quantities they give.
  void reference(const SceneCase& sc) {
    const int level = opt_.quick ? 0 : 2;  // the finest mesh of the matrix
    Strategy def;
    def.contact = {{"method", "cev"}};
    for (auto it = tolerances_.rbegin(); it != tolerances_.rend(); ++it) {
      const auto t0 = Clock::now();
      RunStats st;
      try {
        st = run_once(sc, scene_json(sc, level, def, *it), 20 * opt_.run_seconds);
      } catch (const std::exception& e) {  // the scene cannot be built at this mesh
        std::printf("reference %s: mesh %s cannot be built: %s\n", sc.name.c_str(), label(sc, level).c_str(), e.what());
        return;
      }
      std::printf("reference %s: mesh %s, cev n = inf, tolerance %g: %s (%.2f s)\n", sc.name.c_str(),
                  label(sc, level).c_str(), *it, st.status.c_str(), seconds_since(t0));
      if (st.status == "ok") {
        references_[sc.name] = st.q;
        reference_note_[sc.name] = "finest mesh (" + label(sc, level) + "), cev n = inf, tolerance " + csv_number(*it);
        if (sc.closed_form) reference_note_[sc.name] = sc.closed_form_note + " (" + reference_note_[sc.name] + ")";
        return;
      }
      std::printf("  %s\n", st.reason.c_str());
    }
  }

  // The wall-time limit of one run on a mesh: the larger of --run-seconds and kLimitFactor
  // times the default strategy's time at tolerance 1e-8 there, so that a scene whose every
  // solve is slow is not cut short where a fast one would finish.
  static constexpr double kLimitFactor = 8.0;
  void calibrate(const SceneCase& sc, int level) {
    Strategy def;
    def.contact = {{"method", "cev"}};
    double t = 0.0;
    try {
      t = run_once(sc, scene_json(sc, level, def, 1e-8), 20 * opt_.run_seconds).seconds;
    } catch (const std::exception&) {  // reported by the rows of this mesh
    }
    limits_[{sc.name, level}] = std::max(opt_.run_seconds, kLimitFactor * t);
    std::printf("wall-time limit per run, %s mesh %s: %.1f s\n", sc.name.c_str(), label(sc, level).c_str(),
                limits_[{sc.name, level}]);
  }
  double wall_limit(const SceneCase& sc, int level) const {
    const auto it = limits_.find({sc.name, level});
    return it == limits_.end() ? opt_.run_seconds : it->second;
  }

  void measure(const Task& task, size_t index, size_t total) {
    const SceneCase& sc = *task.scene;
    const Strategy& st = *task.strategy;
    std::string failed_at;  // a looser tolerance already failed
    for (double tol : tolerances_) {
      Row row;
      row.scene = sc.name;
      row.mesh = label(sc, task.level);
      row.level = task.level;
      row.strategy = st.name;
      row.family = st.family;
      row.tolerance = tol;
      if (seconds_since(start_) > 60.0 * opt_.budget_minutes) {
        row.stats.status = "skipped";
        row.stats.reason = "the benchmark's time budget was spent";
      } else if (!failed_at.empty()) {
        row.stats.status = "skipped";
        row.stats.reason = "tolerance " + failed_at + " already ran out of time";
      } else {
        try {
          measure_row(sc, task.level, st, tol, row);
        } catch (const std::exception& e) {  // a scene that cannot be built, or a field missing
          row.stats.status = "failed";
          row.stats.reason = e.what();
        }
        // A run that ran out of time at a looser tolerance would only do so again.
        if (row.stats.status == "timeout") failed_at = csv_number(tol);
      }
      std::lock_guard<std::mutex> lock(mutex_);
      std::printf("[%3zu/%zu %5.0f s] %-6s %-4s %-22s tol %-6g %-11s %8.4f s %6ld solves %7ld newton  err %s\n",
                  index + 1, total, seconds_since(start_), row.scene.c_str(), row.mesh.c_str(), row.strategy.c_str(),
                  tol, row.stats.status.c_str(), row.median_seconds, row.stats.solves, row.stats.newton,
                  csv_number(std::max({row.error.force, row.error.peak, row.error.point})).c_str());
      std::fflush(stdout);
      rows_.push_back(std::move(row));
    }
  }

  void measure_row(const SceneCase& sc, int level, const Strategy& st, double tol, Row& row) {
    const json j = scene_json(sc, level, st, tol);
    std::vector<RunStats> runs;
    std::vector<double> times, cpu;
    for (int r = 0; r < opt_.runs; ++r) {
      runs.push_back(run_once(sc, j, wall_limit(sc, level)));
      times.push_back(runs.back().seconds);
      cpu.push_back(runs.back().cpu_seconds);
      const std::string& status = runs.back().status;
      if (status != "ok" && status != "not reached") break;  // a failure is not timed
    }
    row.runs = static_cast<int>(runs.size());
    row.median_seconds = median(times);
    row.min_seconds = *std::min_element(times.begin(), times.end());
    row.median_cpu_seconds = median(cpu);
    // The run whose time is nearest the median carries the per-step times of the ratio.
    size_t mid = 0;
    for (size_t r = 0; r < runs.size(); ++r)
      if (std::abs(runs[r].seconds - row.median_seconds) < std::abs(runs[mid].seconds - row.median_seconds)) mid = r;
    row.stats = std::move(runs[mid]);
    if (row.stats.status == "ok" || row.stats.status == "not reached") {
      Quantities ref;
      if (references_.count(sc.name)) ref = references_.at(sc.name);
      if (sc.closed_form) {
        Scene scene = read_scene(j);
        RunResult run;
        run.steps = row.stats.steps;
        const Quantities exact = sc.closed_form(scene, run);
        for (auto [mine, theirs] : {std::pair{&ref.force, exact.force},
                                    {&ref.peak, exact.peak},
                                    {&ref.point, exact.point},
                                    {&ref.extent, exact.extent}})
          if (std::isfinite(theirs)) *mine = theirs;
      }
      row.error = errors(row.stats.q, ref);
      const auto [contact, floor] = overhead(j, row.stats, std::max(1, std::min(opt_.runs, 5)));
      row.contact_seconds = contact;
      row.floor_seconds = floor;
      row.overhead_ratio = floor > 0 ? contact / floor : kNaN;
    }
    row.stats.steps.clear();
  }

  // What each scene's quantities mean and what its reference is (read by bench_plots.py).
  void write_scenes() const {
    std::ofstream out(opt_.out / "scenes.csv");
    out << "scene,file,meshes,quantities,reference\n";
    for (const SceneCase& sc : cases_) {
      std::string meshes;
      for (int level : levels_) meshes += (meshes.empty() ? "" : " / ") + label(sc, level);
      const std::string ref = reference_note_.count(sc.name) ? reference_note_.at(sc.name)
                              : sc.closed_form               ? sc.closed_form_note + " (the finest-mesh run failed)"
                                                             : "none: the reference run failed";
      out << sc.name << ',' << sc.file << ',' << csv_text(meshes) << ',' << csv_text(sc.quantities) << ','
          << csv_text(ref) << '\n';
    }
  }

  // Where and how the numbers were taken: other work on the machine shows in the load.
  void write_machine() const {
    std::ofstream out(opt_.out / "machine.txt");
    std::string cpu;
    std::ifstream info("/proc/cpuinfo");
    for (std::string line; std::getline(info, line);)
      if (line.rfind("model name", 0) == 0) {
        cpu = line.substr(line.find(':') + 2);
        break;
      }
    const auto now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    char date[64];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    if (!opt_.label.empty()) out << "measured: " << opt_.label << "\n";
    out << "date: " << date << "\ncpu: " << cpu << " (" << std::thread::hardware_concurrency()
        << " hardware threads)\nworkers: " << opt_.jobs << " (each run on one thread)\nruns per timing: " << opt_.runs
        << "\nwall-time limit per run: the larger of " << opt_.run_seconds << " s and " << kLimitFactor
        << " x the default strategy's time at 1e-8 on the same mesh";
    for (const auto& [key, limit] : limits_)
      out << "; " << key.first << " level " << key.second << ": " << limit << " s";
    out << "\nload average (1, 5, 15 min) at start: " << load_at_start_ << "\nload average at end: " << load_average()
        << "\nduration: " << static_cast<int>(seconds_since(start_)) << " s\n";
  }

  const Row* find(const std::string& scene, int level, const std::string& strategy, double tol) const {
    for (const Row& r : rows_)
      if (r.scene == scene && r.level == level && r.strategy == strategy && r.tolerance == tol) return &r;
    return nullptr;
  }

  // The targets, measured (printed, never asserted); scripts/bench_plots.py writes
  // the same into strategies.md from the CSV.
  void report_targets() const {
    const double tol = 1e-8;
    std::printf("\nTargets (tolerance 1e-8):\n");
    for (const SceneCase& sc : cases_) {
      const int level = opt_.quick ? 0 : 1;
      const Row* cev = find(sc.name, level, "cev-auto-exact", tol);
      const Row* uzawa = find(sc.name, level, "uzawa", tol);
      if (cev && uzawa)
        std::printf("  %s mesh %s: cev auto %ld contact iterations (%s), uzawa %ld (%s)\n", sc.name.c_str(),
                    label(sc, level).c_str(), cev->stats.solves, cev->stats.status.c_str(), uzawa->stats.solves,
                    uzawa->stats.status.c_str());
      if (const Row* def = find(sc.name, level, "cev", tol))
        std::printf("  %s mesh %s: cev %.1f ms, overhead ratio %.2f\n", sc.name.c_str(), label(sc, level).c_str(),
                    1e3 * def->median_seconds, def->overhead_ratio);
    }
    // The paper's scenes as shipped: beam mesh 40 (level 1), sheet mesh 30 (level 0).
    for (const auto& [scene, level] : std::vector<std::pair<std::string, int>>{{"beam", 1}, {"sheet", 0}})
      if (const Row* def = find(scene, level, "cev", tol)) {
        const Row* ssn = find(scene, level, "ssn", tol);
        std::printf("  the paper's %s scene: cev %.1f ms (CPU %.1f ms), %.2f real solves per step; ssn CPU %.1f ms\n",
                    scene.c_str(), 1e3 * def->median_seconds, 1e3 * def->median_cpu_seconds,
                    static_cast<double>(def->stats.solves) / std::max<size_t>(1, def->stats.step_solves.size()),
                    ssn ? 1e3 * ssn->median_cpu_seconds : kNaN);
      }
    for (const SceneCase& sc : cases_)
      if (reference_note_.count(sc.name))
        std::printf("  reference of %s: %s\n", sc.name.c_str(), reference_note_.at(sc.name).c_str());
  }

  Options opt_;
  Clock::time_point start_;
  std::string load_at_start_;
  std::vector<double> tolerances_;
  std::vector<int> levels_;
  std::vector<SceneCase> cases_;
  std::map<std::string, json> base_;
  std::map<std::string, Quantities> references_;
  std::map<std::string, std::string> reference_note_;
  std::map<std::pair<std::string, int>, double> limits_;
  std::mutex mutex_;
  std::vector<Row> rows_;
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace
}  // namespace grip::bench

int main(int argc, char** argv) {
  using namespace grip::bench;
  // The heap settings of `grip` (apps/grip.cpp), so that times do not depend on the heap's history.
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  Options opt;
  auto value = [&](int& i) -> std::string {
    if (i + 1 >= argc) throw std::runtime_error(std::string(argv[i]) + " needs a value");
    return argv[++i];
  };
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--quick") {
        opt.quick = true;
        opt.runs = 1;
        opt.run_seconds = 2.0;
      } else if (a == "--out") {
        opt.out = value(i);
      } else if (a == "--label") {
        opt.label = value(i);
      } else if (a == "--source") {
        opt.source = value(i);
      } else if (a == "--runs") {
        opt.runs = std::max(1, std::stoi(value(i)));
      } else if (a == "--jobs") {
        opt.jobs = std::max(1, std::stoi(value(i)));
      } else if (a == "--budget") {
        opt.budget_minutes = std::stod(value(i));
      } else if (a == "--run-seconds") {
        opt.run_seconds = std::stod(value(i));
      } else if (a == "--scenes") {
        opt.scenes = split(value(i));
      } else if (a == "--strategies") {
        opt.strategies = split(value(i));
      } else if (a == "--levels") {
        for (const std::string& l : split(value(i))) opt.levels.push_back(std::clamp(std::stoi(l), 0, 2));
      } else {
        std::fprintf(stderr,
                     "usage: grip_bench [--quick] [--out DIR] [--runs N] [--jobs N] [--budget MINUTES] "
                     "[--run-seconds S] [--scenes "
                     "beam,sheet,hertz,cattaneo-mindlin,cantilever,strip-cylinder,sliding-block,beam-mu0,sheet-mu0,"
                     "sliding-block-mu0] [--strategies cev,ssn,...] "
                     "[--levels 0,1,2] "
                     "[--source DIR] [--label TEXT]\n");
        return a == "--help" ? 0 : 2;
      }
    }
    return Bench(opt).run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "grip_bench: %s\n", e.what());
    return 1;
  }
}
