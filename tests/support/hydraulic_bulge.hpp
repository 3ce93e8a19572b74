#pragma once
// The hydraulic bulge of a flat circular diaphragm of radius a clamped at its rim, a
// rigid-plastic membrane of Hill's 1979 material with normal anisotropy (flow theory, as in Hill
// 1950 and Chakrabarty and Alexander 1970), computed independently of the finite elements
// (docs/verification.md#hydraulic-bulge): the meridian in the material radius R in [0, a] on a
// fixed grid, marched in pole strains; each step is a shooting problem from the pole to the rim.
//
// Along the meridian, with r the current radius, z the height, phi the slope, lambda1 = ds/dR
// and lambda2 = r / R the stretches, t = t0 / (lambda1 lambda2), T1 = t sigma1 and T2 = t sigma2:
//   dr/dR = lambda1 cos phi,  dz/dR = -lambda1 sin phi,  d(r T1)/dR = T2 lambda1 cos phi
// (tangential equilibrium), and the equilibrium of the cap inside r under the pressure p,
//   2 pi r T1 sin phi = pi r^2 p.
// The stresses follow the flow rule of the yield surface |s1 + s2|^M + (1 + 2r) |s1 - s2|^M =
// 2 (1 + r) sigma_bar^M from the strain increments of the step, d1 = ln(lambda1 /
// lambda1_old), d2 = ln(lambda2 / lambda2_old) (backward Euler, as a rigid-plastic law is
// integrated), with the flow stress H (a0 + eps_bar)^n at the end of the step. Given r and T1
// at a point, lambda1 is the root of T1(lambda1) on its rising branch. Heun's method (second
// order) on the grid's nodes, where the history lives. The march is driven by the pole strain:
// each step is then a one-dimensional search for the pressure that brings the meridian to the
// rim's radius (driven by the height, a two-unknown Newton on pole stretch and pressure met the
// kinks of the rigid-plastic law in its trial shots and stalled).
#include <cmath>
#include <stdexcept>
#include <vector>

namespace grip::testing {

struct BulgeMaterial {
  double r = 1.0;  // normal anisotropy
  double M = 2.0;  // exponent of Hill's 1979 yield function
  double H = 1.0;  // flow stress H (a0 + eps_bar)^n
  double a0 = 1e-4;
  double n = 0.2;
};

struct BulgeState {
  double height = 0.0;       // of the pole above the rim
  double pole_strain = 0.0;  // ln of the pole's (equal-biaxial) stretch
  double pressure = 0.0;
};

namespace bulge_detail {

// Stresses per unit flow stress for strain increments (d1, d2), normal to the yield surface,
// and the effective strain increment, the plastic work per unit flow stress s1 d1 + s2 d2.
struct Flow {
  double s1, s2, deps;
};
inline Flow hill_flow(const BulgeMaterial& m, double d1, double d2) {
  const double q = 1 / (m.M - 1), sum = d1 + d2, diff = d1 - d2;
  const double S = std::copysign(std::pow(std::abs(sum), q), sum);
  const double T = std::copysign(std::pow(std::abs(diff) / (1 + 2 * m.r), q), diff);
  const double size = std::pow(std::abs(S), m.M) + (1 + 2 * m.r) * std::pow(std::abs(T), m.M);
  if (!(size > 0)) return {0.0, 0.0, 0.0};
  const double k = std::pow(2 * (1 + m.r) / size, 1 / m.M);
  return {k * (S + T) / 2, k * (S - T) / 2, k * (S * sum + T * diff) / 2};
}

struct Bulge {
  BulgeMaterial m;
  double a, t0;
  int nodes;                                    // grid nodes R_i = a i / (nodes - 1)
  std::vector<double> l1, l2, eps;              // committed stretches and effective strain
  std::vector<double> l1_new, l2_new, eps_new;  // of the last shot

  double R(int i) const { return a * i / (nodes - 1); }
  double flow_stress(double e) const { return m.H * std::pow(m.a0 + e, m.n); }

  // Tensions at node i for the stretches (lambda1, lambda2); deps its effective increment.
  void tensions(int i, double lambda1, double lambda2, double& T1, double& T2, double& deps) const {
    const Flow f = hill_flow(m, std::log(lambda1 / l1[i]), std::log(lambda2 / l2[i]));
    const double t = t0 / (lambda1 * lambda2), sigma = flow_stress(eps[i] + f.deps);
    T1 = t * sigma * f.s1;
    T2 = t * sigma * f.s2;
    deps = f.deps;
  }

  // lambda1 at node i such that the meridional tension is T1, on the rising branch from the
  // uniaxial hoop state (sigma1 = 0 at d1 = -r d2 / (1 + r)). NaN if the tension is past its top.
  double meridional_stretch(int i, double lambda2, double T1) const {
    const double d2 = std::log(lambda2 / l2[i]);
    auto excess = [&](double d1) {
      double t1, t2, de;
      tensions(i, l1[i] * std::exp(d1), lambda2, t1, t2, de);
      return t1 - T1;
    };
    double lo = -m.r * d2 / (1 + m.r), f_lo = excess(lo), step = 1e-6 + 1e-3 * std::abs(d2), hi = lo + step;
    double f_hi = excess(hi);
    while (f_hi < 0) {
      if (step > 2) return NAN;
      const double f_before = f_hi;
      lo = hi;
      f_lo = f_hi;
      step *= 2;
      hi = lo + step;
      f_hi = excess(hi);
      if (f_hi < f_before) return NAN;  // past the top of T1(lambda1)
    }
    // Illinois' false position on [lo, hi].
    int side = 0;
    for (int k = 0; k < 200 && hi - lo > 1e-15; ++k) {
      const double x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo), f = excess(x);
      if (f == 0) return l1[i] * std::exp(x);
      if ((f < 0) == (f_lo < 0)) {
        lo = x;
        f_lo = f;
        if (side == -1) f_hi /= 2;
        side = -1;
      } else {
        hi = x;
        f_hi = f;
        if (side == 1) f_lo /= 2;
        side = 1;
      }
    }
    return l1[i] * std::exp(0.5 * (lo + hi));
  }

  // The rates (dr, dQ, dz)/dR at node i, Q = r T1; the pole is the limit R -> 0.
  bool rates(int i, double pole_stretch, double p, const double y[3], double out[3], double* lambda1,
             double* deps) const {
    double lambda2, T1, T2, de;
    if (i == 0) {
      lambda2 = pole_stretch;
      *lambda1 = pole_stretch;
      tensions(0, *lambda1, lambda2, T1, T2, de);
    } else {
      if (!(y[0] > 0 && y[1] > 0)) return false;
      lambda2 = y[0] / R(i);
      T1 = y[1] / y[0];
      *lambda1 = meridional_stretch(i, lambda2, T1);
      if (!std::isfinite(*lambda1)) return false;
      // The hoop tension from the flow rule's stress ratio; at the rim (d2 = 0) an element that
      // does not stretch is rigid and carries any T1 below its yield, at the plane-strain ratio.
      const bulge_detail::Flow f = hill_flow(m, std::log(*lambda1 / l1[i]), std::log(lambda2 / l2[i]));
      const bulge_detail::Flow plane = hill_flow(m, 1.0, 0.0);
      T2 = T1 * (f.s1 > 0 ? f.s2 / f.s1 : plane.s2 / plane.s1);
      de = f.deps;
    }
    const double sine = i == 0 ? 0.0 : p * y[0] / (2 * T1);
    if (!(std::abs(sine) < 1)) return false;  // curved past the vertical
    const double cosine = std::sqrt(1 - sine * sine);
    out[0] = *lambda1 * cosine;
    out[1] = T2 * *lambda1 * cosine;
    out[2] = -*lambda1 * sine;
    if (deps) *deps = de;
    return true;
  }

  // Shoots from the pole: (r / a - 1, the pole's height over the rim / a); keeps the stretches
  // and strains it passed in l1_new, l2_new, eps_new.
  bool shoot(double pole_stretch, double p, double misfit[2]) {
    double y[3] = {0.0, 0.0, 0.0}, k1[3], k2[3], y2[3], lambda1, de;
    const double step = R(1);
    l1_new.assign(nodes, 0.0);
    l2_new.assign(nodes, pole_stretch);
    eps_new.assign(nodes, 0.0);
    for (int i = 0; i + 1 < nodes; ++i) {
      if (!rates(i, pole_stretch, p, y, k1, &lambda1, &de)) return false;
      l1_new[i] = lambda1;
      if (i > 0) l2_new[i] = y[0] / R(i);
      eps_new[i] = eps[i] + de;
      for (int c = 0; c < 3; ++c) y2[c] = y[c] + step * k1[c];
      if (!rates(i + 1, pole_stretch, p, y2, k2, &lambda1, nullptr)) return false;
      for (int c = 0; c < 3; ++c) y[c] += 0.5 * step * (k1[c] + k2[c]);
    }
    if (!rates(nodes - 1, pole_stretch, p, y, k1, &lambda1, &de)) return false;
    l1_new[nodes - 1] = lambda1;
    l2_new[nodes - 1] = y[0] / a;
    eps_new[nodes - 1] = eps[nodes - 1] + de;
    misfit[0] = y[0] / a - 1;
    misfit[1] = -y[2] / a;
    return true;
  }
};

}  // namespace bulge_detail

// The bulge marched through the pole strains `pole_strains` (rising, from the flat sheet): the
// pole height and the pressure at each. `nodes` grid points along the radius.
inline std::vector<BulgeState> hydraulic_bulge(const BulgeMaterial& material, double radius, double thickness,
                                               const std::vector<double>& pole_strains, int nodes = 400) {
  bulge_detail::Bulge b{material, radius, thickness, nodes, {}, {}, {}, {}, {}, {}};
  b.l1.assign(nodes, 1.0);
  b.l2.assign(nodes, 1.0);
  b.eps.assign(nodes, 0.0);
  std::vector<BulgeState> out;
  for (size_t k = 0; k < pole_strains.size(); ++k) {
    const double stretch = std::exp(pole_strains[k]);
    // For a given pole stretch, a higher pressure curves the meridian more and brings it to the
    // rim's radius sooner: r(a) falls with p (a failed shot curved past the vertical). The
    // first guess: a spherical cap (Hill 1950), then the last two pressures extrapolated.
    double p;
    if (k < 2) {
      const double h = radius * std::sqrt(stretch - 1), rho = (radius * radius + h * h) / (2 * h);
      p = 2 * thickness / (stretch * stretch) * b.flow_stress(2 * pole_strains[k]) / rho;
    } else {
      const double s = (pole_strains[k] - pole_strains[k - 1]) / (pole_strains[k - 1] - pole_strains[k - 2]);
      p = out[k - 1].pressure * std::pow(out[k - 1].pressure / out[k - 2].pressure, s);
    }
    double misfit[2];
    auto rim = [&](double pressure) {  // r(a) / a - 1, or -1 for a shot that failed
      return b.shoot(stretch, pressure, misfit) ? misfit[0] : -1.0;
    };
    double lo = p, hi = p, f_lo = rim(lo), f_hi = f_lo;
    for (int k2 = 0; f_lo <= 0 && k2 < 200; ++k2) f_lo = rim(lo /= 1.05);
    for (int k2 = 0; f_hi > 0 && k2 < 200; ++k2) f_hi = rim(hi *= 1.05);
    if (!(f_lo > 0 && f_hi <= 0)) throw std::runtime_error("hydraulic_bulge: no pressure brackets the rim");
    // Illinois' false position; a failed shot (f = -1) only narrows the bracket by bisection.
    int side = 0;
    for (int it = 0; it < 200 && hi - lo > 1e-14 * hi; ++it) {
      const bool failed_hi = f_hi == -1.0;
      const double x = failed_hi ? 0.5 * (lo + hi) : (lo * f_hi - hi * f_lo) / (f_hi - f_lo), f = rim(x);
      if (f == 0) {
        lo = hi = x;
        break;
      }
      if (f > 0) {
        lo = x;
        f_lo = f;
        if (side == -1) f_hi /= 2;
        side = -1;
      } else {
        hi = x;
        f_hi = f;
        if (side == 1) f_lo /= 2;
        side = 1;
      }
    }
    p = 0.5 * (lo + hi);
    if (!b.shoot(stretch, p, misfit) || !(std::abs(misfit[0]) < 1e-9))
      throw std::runtime_error("hydraulic_bulge: the shot did not reach the rim");
    b.l1 = b.l1_new;
    b.l2 = b.l2_new;
    b.eps = b.eps_new;
    out.push_back({misfit[1] * radius, pole_strains[k], p});
  }
  return out;
}

}  // namespace grip::testing
