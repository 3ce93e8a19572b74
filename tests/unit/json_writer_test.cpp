// The result writer's numbers: every double reads back as itself (std::from_chars and nlohmann
// both parse exactly), as a floating-point number, with the same shortest significant digits
// std::to_chars finds (so nothing longer than needed is written).
#include "solver/io/json_writer.hpp"
#include "solver/io/result.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <string>

namespace grip {
namespace {

std::string written(double v) {
  char buf[kMaxNumberChars];
  return std::string(buf, write_number(buf, v));
}

// The significant digits of a decimal number's text ("-0.00120e+05" -> "12").
std::string significant_digits(const std::string& text) {
  std::string d;
  for (char c : text.substr(0, text.find_first_of("eE")))
    if (c >= '0' && c <= '9' && !(d.empty() && c == '0')) d += c;
  while (!d.empty() && d.back() == '0') d.pop_back();
  return d;
}

void expect_round_trip(double v) {
  const std::string text = written(v);
  double back = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), back);
  ASSERT_EQ(r.ec, std::errc()) << text;
  EXPECT_EQ(r.ptr, text.data() + text.size()) << text;
  EXPECT_EQ(std::bit_cast<uint64_t>(back), std::bit_cast<uint64_t>(v)) << text;
  const nlohmann::json parsed = nlohmann::json::parse(text);
  EXPECT_TRUE(parsed.is_number_float()) << text;
  EXPECT_EQ(std::bit_cast<uint64_t>(parsed.get<double>()), std::bit_cast<uint64_t>(v)) << text;
  char shortest[64];
  char* end = std::to_chars(shortest, shortest + sizeof shortest, v, std::chars_format::scientific).ptr;
  EXPECT_EQ(significant_digits(text), significant_digits(std::string(shortest, static_cast<size_t>(end - shortest))))
      << text;
}

TEST(JsonNumbers, EveryBitPatternSampledReadsBackAsItself) {
  std::mt19937_64 bits(20261125);
  for (int i = 0; i < 200000; ++i) {
    const double v = std::bit_cast<double>(bits());
    if (std::isfinite(v)) expect_round_trip(v);
  }
}

TEST(JsonNumbers, ResultLikeValuesReadBackAsThemselves) {
  // Displacements, coordinates, stresses: decades from 1e-12 to 1e6, and decimal-looking values.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-1, 1);
  std::uniform_int_distribution<int> decade(-12, 6);
  for (int i = 0; i < 200000; ++i) expect_round_trip(mantissa(rng) * std::pow(10.0, decade(rng)));
  for (int k = -400; k <= 400; ++k) expect_round_trip(k * 0.025);
}

TEST(JsonNumbers, EdgeValuesAndTheirForms) {
  EXPECT_EQ(written(0.0), "0.0");
  EXPECT_EQ(written(-0.0), "-0.0");
  EXPECT_EQ(written(100.0), "100.0");
  EXPECT_EQ(written(0.1), "0.1");
  EXPECT_EQ(written(-2.5), "-2.5");
  EXPECT_EQ(written(1e-5), "1e-05");
  EXPECT_EQ(written(1e-6), "1e-06");
  EXPECT_EQ(written(0.000123), "0.000123");
  EXPECT_EQ(written(1e16), "1e+16");
  EXPECT_EQ(written(1e17), "1e+17");
  EXPECT_EQ(written(1.5e300), "1.5e+300");
  EXPECT_EQ(written(std::numeric_limits<double>::quiet_NaN()), "null");
  EXPECT_EQ(written(-std::numeric_limits<double>::infinity()), "null");
  for (double v : {std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
                   std::numeric_limits<double>::min(), std::numeric_limits<double>::denorm_min(),
                   -std::numeric_limits<double>::denorm_min(), 1e22, 1e23, 9007199254740993.0, 0.3, 2.0 / 3.0})
    expect_round_trip(v);
  EXPECT_EQ(written(-2.2250738585072014e-308).size(), 24u);  // the longest form
}

TEST(JsonWriter, SmallValuesReadBackAsTheDocument) {
  const nlohmann::json doc = {{"b", {1, -2, 3.25, 1e-7}},
                              {"a", "plain"},
                              {"c", "quote \" and \\ and \n"},
                              {"d", nullptr},
                              {"e", true},
                              {"f", {{"z", 0.1}, {"y", std::vector<int>{}}}},
                              {"g", 18446744073709551615ull},
                              {"h", "\u00e9t\u00e9"}};
  std::ostringstream out;
  {
    JsonWriter w(out);
    w.value(doc);
  }
  EXPECT_EQ(nlohmann::json::parse(out.str()), doc);
  EXPECT_EQ(out.str().substr(0, 5), "{\"a\":");  // keys in nlohmann's order
}

// field_value takes a path without text where that is exact: it must give the double that
// rounding v's decimal to kFieldDigits digits and reading it back gives (the text way), bit for bit.
double field_value_by_text(double v) {
  if (!std::isfinite(v) || v == 0) return v;
  char text[32];
  const char* end = std::to_chars(text, text + sizeof text, v, std::chars_format::scientific, kFieldDigits - 1).ptr;
  double rounded = v;
  std::from_chars(text, end, rounded);
  return rounded;
}

TEST(FieldValue, EqualsTheDecimalRoundedAndReadBack) {
  std::mt19937_64 random(34);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-40, 40);
  std::uniform_int_distribution<std::uint64_t> bits;
  for (int i = 0; i < 2000000; ++i) {
    const double scaled = unit(random) * std::pow(10.0, exponent(random));
    ASSERT_EQ(std::bit_cast<std::uint64_t>(field_value(scaled)),
              std::bit_cast<std::uint64_t>(field_value_by_text(scaled)))
        << scaled;
    const double any = std::bit_cast<double>(bits(random));  // every binade, subnormals, NaN
    if (std::isnan(any)) continue;
    ASSERT_EQ(std::bit_cast<std::uint64_t>(field_value(any)), std::bit_cast<std::uint64_t>(field_value_by_text(any)))
        << any;
  }
  // Halves of the 7th digit (ties) and near-ties, powers of ten and their neighbours.
  for (double v : {1.0000005, 1.00000050000001, 2.5e-7, 9999999.5, 0.99999995, 999999.95, 1e22, 1e23, 1e-22, 1e-23,
                   123456.75, 5e-324, 1.7976931348623157e308}) {
    for (double w : {v, std::nextafter(v, 0.0), std::nextafter(v, 2 * v), -v})
      EXPECT_EQ(std::bit_cast<std::uint64_t>(field_value(w)), std::bit_cast<std::uint64_t>(field_value_by_text(w)))
          << w;
  }
}

// A step's contact points are written without a JSON document: the same text as the document
// contact_points_json builds, written by value(), for one body and for several (body, master).
TEST(ContactPoints, WrittenAsTheirDocument) {
  ContactPointRow one{
      3,      "floor",     "slip",          {},     {}, Vec2(0.1, -2.5e-9), Vec2(1.0 / 3, 100), Vec2(0, -1), 12.5,
      -1e300, 1234567.891, -0.000123456789, -3e-12, 0.0};
  ContactPointRow two = one;
  two.node = 41;
  two.obstacle = "quote \" pair";
  two.state = "stick";
  two.body = "upper";
  two.master = "lower\\block";
  two.several_bodies = true;
  for (const std::vector<ContactPointRow>& rows :
       {std::vector<ContactPointRow>{}, std::vector<ContactPointRow>{one}, std::vector<ContactPointRow>{one, two}}) {
    StepOutput step;
    step.summary = nlohmann::json::object();
    step.contact_points = rows;
    std::ostringstream streamed, document;
    write_step(streamed, step);
    {
      JsonWriter w(document);
      w.value(nlohmann::json{{"contact_points", contact_points_json(rows)}});
    }
    EXPECT_EQ(streamed.str(), document.str());
  }
}

}  // namespace
}  // namespace grip
