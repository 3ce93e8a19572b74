// Richardson extrapolation (server/richardson.hpp) against sequences whose limit and order are
// known in closed form: f(h) = f* + C h^p (+ a higher term), on halved and on uneven sizes.
#include <gtest/gtest.h>

#include <cmath>

#include "server/richardson.hpp"

namespace grip::server {
namespace {

std::vector<double> sampled(const std::vector<double>& h, double limit, double c, double p, double d = 0,
                            double q = 0) {
  std::vector<double> f;
  for (double x : h) f.push_back(limit + c * std::pow(x, p) + d * std::pow(x, q));
  return f;
}

TEST(Richardson, APurePowerGivesItsOrderAndItsLimitOnHalvedSizes) {
  const std::vector<double> h = {1, 0.5, 0.25};
  const Richardson r = richardson(sampled(h, 2.0, 3.0, 2.0), h);
  ASSERT_TRUE(r.order && r.extrapolated);
  EXPECT_NEAR(*r.order, 2.0, 1e-12);
  EXPECT_NEAR(*r.extrapolated, 2.0, 1e-12);
  // Each level's error is C h^p / f*.
  for (size_t k = 0; k < h.size(); ++k) EXPECT_NEAR(*r.estimated_error[k], 3.0 * h[k] * h[k] / 2.0, 1e-12);
  EXPECT_FALSE(r.asymptotic);  // three levels: one order, nothing to compare it with
  EXPECT_FALSE(r.order_ratio);
}

TEST(Richardson, UnevenRatiosAreSolvedForTheOrder) {
  const std::vector<double> h = {1, 0.6, 0.25};  // r21 = 1.67, r32 = 2.4
  const Richardson r = richardson(sampled(h, -1.5, 0.8, 1.5), h);
  ASSERT_TRUE(r.order && r.extrapolated);
  EXPECT_NEAR(*r.order, 1.5, 1e-9);
  EXPECT_NEAR(*r.extrapolated, -1.5, 1e-9);
}

// f* + h^2 + 10 h^4 on h = 1 ... 1/64: the observed orders fall toward 2 (3.71, 3.21, 2.58,
// 2.19, 2.05), so that the four coarsest levels are outside the asymptotic range (orders 3.71 and
// 3.21: ratio 0.87) and all seven inside it (2.05 / 2.19 = 0.94); the extrapolation removes the
// leading term but for its order's excess (2.05, not 2): 27 times closer to the limit than the
// finest level (9.0e-6 against 2.4e-4).
TEST(Richardson, AHigherTermIsSeenAsOrdersApproachingTheLeadingOne) {
  std::vector<double> h;
  for (double x = 1; x >= 1.0 / 64; x /= 2) h.push_back(x);
  const std::vector<double> f = sampled(h, 1.0, 1.0, 2.0, 10.0, 4.0);
  const Richardson r = richardson(f, h);
  ASSERT_EQ(r.orders.size(), 5u);
  for (size_t k = 0; k < r.orders.size(); ++k) {
    ASSERT_TRUE(r.orders[k]);
    EXPECT_GT(*r.orders[k], 2.0);
    if (k) EXPECT_LT(*r.orders[k], *r.orders[k - 1]);
  }
  // Halved sizes: p = log2(e(x) / e(x / 2)) with e(x) = f(x) - f(x / 2) = 3/4 x^2 + 150/16 x^4.
  auto e = [](double x) { return 0.75 * x * x + 9.375 * x * x * x * x; };
  EXPECT_NEAR(*r.order, std::log2(e(1.0 / 16) / e(1.0 / 32)), 1e-9);
  ASSERT_TRUE(r.asymptotic && r.order_ratio);
  EXPECT_TRUE(*r.asymptotic) << *r.order_ratio;
  EXPECT_NEAR(*r.order_ratio, *r.orders[4] / *r.orders[3], 1e-15);
  EXPECT_LT(std::abs(*r.extrapolated - 1.0), 0.05 * std::abs(f.back() - 1.0));
  const Richardson coarse = richardson({f[0], f[1], f[2], f[3]}, {h[0], h[1], h[2], h[3]});
  ASSERT_TRUE(coarse.asymptotic);
  EXPECT_FALSE(*coarse.asymptotic) << *coarse.order_ratio;
  EXPECT_NEAR(*coarse.order_ratio, std::log2(e(0.5) / e(0.25)) / std::log2(e(1) / e(0.5)), 1e-9);
}

TEST(Richardson, OscillatingOrFlatSequencesHaveNoOrder) {
  const std::vector<double> h = {1, 0.5, 0.25};
  const Richardson oscillating = richardson({1.0, 1.2, 1.1}, h);
  EXPECT_FALSE(oscillating.order);
  EXPECT_FALSE(oscillating.extrapolated);
  EXPECT_FALSE(oscillating.estimated_error[2]);
  const Richardson flat = richardson({3.0, 3.0, 3.0}, h);  // converged to every digit
  EXPECT_FALSE(flat.order);
  ASSERT_TRUE(flat.extrapolated);
  EXPECT_EQ(*flat.extrapolated, 3.0);
  EXPECT_EQ(*flat.estimated_error[0], 0.0);
  const Richardson half_flat = richardson({2.0, 3.0, 3.0}, h);
  EXPECT_FALSE(half_flat.order);
  EXPECT_FALSE(half_flat.extrapolated);
  const Richardson two = richardson({1.0, 2.0}, {1, 0.5});
  EXPECT_TRUE(two.orders.empty());
  EXPECT_FALSE(two.extrapolated);
}

}  // namespace
}  // namespace grip::server
