// The continuum's element kernels over a thread team (ContinuumBody::set_parallel): computed on
// the threads, summed on the calling thread in element order, so the force and every tangent
// entry are the serial ones to the last bit, in every kernel (plain, F-bar, the mixed element's
// dilatation, the hoop law of axisymmetry) and with a plastic history read by the threads; and a
// whole strip wrapped onto a cylinder solves to the same bits on two threads as on one.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <memory>

#include "apps/thread_team.hpp"
#include "solver/elements/continuum.hpp"
#include "solver/io/scene.hpp"
#include "solver/stepping/load_stepping.hpp"
#include "tests/support/strips.hpp"

namespace grip {
namespace {

// A team of two threads that counts the tasks it was given: the parallel path must be taken.
struct CountedTeam {
  std::shared_ptr<ThreadTeam> team = std::make_shared<ThreadTeam>(2);
  std::shared_ptr<std::atomic<int>> tasks = std::make_shared<std::atomic<int>>(0);
  ParallelFor parallel() const {
    return [team = team, tasks = tasks](int count, const std::function<void(int)>& task) {
      *tasks += count;
      team->run(count, task);
    };
  }
};

// The strip scene's body with another element, analysis, law or constraint: a block of
// nx x ny cells, 1 x 0.2 (its left side held), for the kernels only.
Scene block_scene(const std::string& element, const std::string& analysis, const nlohmann::json& material, int nx,
                  int ny, const std::string& incompressibility = "none") {
  nlohmann::json j = testing::strip_scene({});
  auto& body = j["body"];
  body["element"] = element;
  body["analysis"] = analysis;
  body["material"] = material;
  body["mesh"]["rectangle"] = {{"origin", {0.5, 0.0}}, {"size", {1.0, 0.2}}, {"divisions", {nx, ny}}};
  if (incompressibility != "none") body["incompressibility"] = incompressibility;
  return read_scene(j);
}

// A smooth state with stretch, shear and bending: every point strained differently.
Vector bent_state(const ContinuumBody& body, double scale) {
  Vector q(body.dof_count());
  for (int n = 0; n < body.node_count(); ++n) {
    const Vec2& x = body.mesh().nodes[n];
    q[ContinuumBody::node_dof(n, 0)] = scale * (0.04 * x.x() + 0.03 * x.y() + 0.01 * std::sin(7 * x.x()));
    q[ContinuumBody::node_dof(n, 1)] = scale * (-0.05 * x.x() * x.x() + 0.02 * x.y() * x.x());
  }
  return q;
}

struct Assembled {
  Vector force, force_only;
  Triplets tangent;
};

Assembled assemble(const ContinuumBody& body, const Vector& q) {
  Assembled a{Vector::Zero(body.dof_count()), Vector::Zero(body.dof_count()), {}};
  TripletSink sink(a.tangent);
  body.internal_force(q, a.force, &sink);
  body.internal_force(q, a.force_only, nullptr);  // the line search's residual
  return a;
}

void expect_bit_identical(const Assembled& serial, const Assembled& teamed) {
  ASSERT_EQ(serial.force.size(), teamed.force.size());
  EXPECT_EQ((serial.force - teamed.force).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((serial.force_only - teamed.force_only).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((serial.force - serial.force_only).cwiseAbs().maxCoeff(), 0.0);
  ASSERT_EQ(serial.tangent.size(), teamed.tangent.size());
  size_t differ = 0;
  for (size_t k = 0; k < serial.tangent.size(); ++k) {
    const auto &s = serial.tangent[k], &t = teamed.tangent[k];
    differ += s.row() != t.row() || s.col() != t.col() || s.value() != t.value();
  }
  EXPECT_EQ(differ, 0u) << "of " << serial.tangent.size() << " tangent entries";
}

struct Case {
  const char* name;
  std::string element, analysis;
  nlohmann::json material;
  int nx, ny;
  std::string incompressibility = "none";
};

TEST(ParallelAssembly, ForceAndTangentAreTheSerialOnesToTheBit) {
  const nlohmann::json svk = {{"young", 1.5e6}, {"poisson", 0.3}, {"law", "saint_venant_kirchhoff"}};
  const nlohmann::json rubber = {{"young", 3.0}, {"poisson", 0.49}, {"law", "neo_hookean"}};
  const nlohmann::json j2 = {{"young", 2e5},
                             {"poisson", 0.3},
                             {"law", "j2_plasticity"},
                             {"yield_stress", 200.0},
                             {"hardening", {{"linear", 1e3}}}};
  const Case cases[] = {
      {"q9 plane strain", "q9", "plane_strain", svk, 50, 6},
      {"q4 F-bar, plastic", "q4", "plane_strain", j2, 50, 12, "f_bar"},
      {"t6 mixed (dilatation)", "t6", "plane_strain", rubber, 20, 10, "mixed"},
      {"q9 axisymmetric, plastic (hoop law)", "q9", "axisymmetric", j2, 30, 8},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Scene scene = block_scene(c.element, c.analysis, c.material, c.nx, c.ny, c.incompressibility);
    auto& body = dynamic_cast<ContinuumBody&>(*scene.problem.body);
    const bool plastic = c.material["law"] == "j2_plasticity";
    if (plastic) {  // a committed history that differs from point to point
      body.commit(bent_state(body, 1.0));
      double flowed = 0.0;
      for (const PointHistory& h : body.committed_history()) flowed = std::max(flowed, h.equivalent_plastic_strain);
      ASSERT_GT(flowed, 1e-3) << "the history must hold plastic strain";
    }
    const Vector q = bent_state(body, plastic ? 1.3 : 1.0);
    const Assembled serial = assemble(body, q);
    CountedTeam team;
    body.set_parallel(team.parallel());
    const Assembled teamed = assemble(body, q);
    EXPECT_GT(team.tasks->load(), 2) << "the kernels did not take the threads";
    expect_bit_identical(serial, teamed);
    // The order the tasks run in does not matter: last to first on this thread.
    int reversed_tasks = 0;
    body.set_parallel([&](int count, const std::function<void(int)>& task) {
      for (int k = count - 1; k >= 0; --k, ++reversed_tasks) task(k);
    });
    expect_bit_identical(serial, assemble(body, q));
    EXPECT_GT(reversed_tasks, 2);
  }
}

TEST(ParallelAssembly, SmallMeshStaysOnTheCallingThread) {
  Scene scene = block_scene("q4", "plane_strain", {{"young", 1.0}, {"poisson", 0.3}, {"law", "neo_hookean"}}, 10, 4);
  auto& body = dynamic_cast<ContinuumBody&>(*scene.problem.body);
  CountedTeam team;
  body.set_parallel(team.parallel());
  const Assembled a = assemble(body, bent_state(body, 1.0));
  EXPECT_EQ(team.tasks->load(), 0);  // 40 elements x 4 points: below kParallelPoints
  EXPECT_GT(a.force.norm(), 0.0);
}

// The strip of strip-on-cylinder.json refined to 60 x 4 (2,160 points), wrapped in 8 steps: every
// step's displacements, contact forces and element stresses the same bits on two threads.
TEST(ParallelAssembly, StripOnCylinderSolvesToTheSameBitsOnTwoThreads) {
  testing::StripSpec spec;
  spec.along = 60;
  spec.across = 4;
  spec.radius = 0.4;
  spec.friction = 0.3;
  spec.steps = 8;
  Scene serial = read_scene(testing::strip_scene(spec));
  Scene teamed = read_scene(testing::strip_scene(spec));
  CountedTeam team;
  teamed.params.newton.parallel = team.parallel();
  assemble_on(*teamed.problem.body, teamed.params.newton.parallel);
  const RunResult a = run_load_steps(serial.problem, serial.steps, serial.params);
  const RunResult b = run_load_steps(teamed.problem, teamed.steps, teamed.params);
  ASSERT_TRUE(a.completed) << a.reason;
  ASSERT_TRUE(b.completed) << b.reason;
  EXPECT_GT(team.tasks->load(), 100) << "the kernels did not take the threads";
  EXPECT_EQ(a.counters.newton_iterations, b.counters.newton_iterations);
  EXPECT_EQ(a.counters.solves, b.counters.solves);
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (size_t k = 0; k < a.steps.size(); ++k) {
    EXPECT_EQ((a.steps[k].state.q - b.steps[k].state.q).cwiseAbs().maxCoeff(), 0.0) << "step " << k;
    EXPECT_EQ((a.steps[k].p - b.steps[k].p).cwiseAbs().maxCoeff(), 0.0) << "step " << k;
  }
  const Vector& q_last = a.steps.back().state.q;
  EXPECT_GT(q_last.cwiseAbs().maxCoeff(), 0.5);  // the tip has come down onto the cylinder
  const FieldTable sa = serial.problem.body->element_fields(q_last);
  const FieldTable sb = teamed.problem.body->element_fields(b.steps.back().state.q);
  ASSERT_EQ(sa.rows.size(), sb.rows.size());
  for (size_t e = 0; e < sa.rows.size(); ++e) ASSERT_EQ(sa.rows[e], sb.rows[e]) << "element " << e;
}

}  // namespace
}  // namespace grip
