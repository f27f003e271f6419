// Every density type of the scene format's table (scene/density_types.h), through the Density
// interface alone (media/density.h): its range over a box contains its value at every point of
// the box, and the table makes each type from its own keys.

#include "nimbus/media/density.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/math/rng.h"
#include "nimbus/scene/density_types.h"
#include "support/vdb_grids.h"

namespace nimbus {
namespace density_test {

TEST(Density, EveryTypesRangeHoldsItsValues) {
  // The holding object's function: a unit sphere's 1 − |x|², evaluated as the octree does.
  const Tape tape = compile(*make_shape(QuadricNode{sphere({0, 0, 0}, 1)}));
  const JsonOrigin origin{"test", {}};
  // The types' required keys: a VDB grid (a rippled ball a little larger than the sphere).
  const test::TempDir dir("density_test");
  test::write_ball_vdb(dir.file("ball.vdb"), 12, 0.1, {0, 0, 0});
  const nlohmann::json required = {{"vdb", {{"file", dir.file("ball.vdb")}}}};
  Rng rng(3);
  for (const DensityType& type : density_types()) {
    SCOPED_TRACE(std::string(type.name));
    const std::string name(type.name);
    const nlohmann::json params =
        required.contains(name) ? required[name] : nlohmann::json::object();
    JsonObject o(JsonValue(params, "/density", origin));
    std::vector<InputFile> inputs;
    const DensityPtr density = type.read(o)(inputs);
    ASSERT_NE(density, nullptr);
    int inside = 0;
    for (int b = 0; b < 300; ++b) {
      Vec3 lo, hi;
      for (int k = 0; k < 3; ++k) {
        const double a = -1.2 + 2.4 * rng.uniform(), w = 0.6 * rng.uniform();
        lo[k] = a;
        hi[k] = a + w;
      }
      const Box box{lo, hi};
      const Interval F = evaluate(tape, box);
      const Interval r = density->range(box, F);
      ASSERT_LE(r.lo, r.hi);
      for (int i = 0; i < 50; ++i) {
        Vec3 x;
        for (int k = 0; k < 3; ++k) x[k] = lo[k] + rng.uniform() * (hi[k] - lo[k]);
        const double f = evaluate(tape, x);
        if (f <= 0) continue;  // outside the object no density is asked for
        ++inside;
        const double v = density->value(x, f);
        EXPECT_GE(v, 0);
        EXPECT_LE(r.lo, v) << "box " << b;
        EXPECT_GE(r.hi, v) << "box " << b;
      }
    }
    EXPECT_GT(inside, 2000);
  }
}

TEST(Density, TheTableNamesEachTypeOnce) {
  const auto names = density_type_names();
  ASSERT_EQ(names.size(), density_types().size());
  for (size_t i = 0; i < names.size(); ++i)
    for (size_t j = i + 1; j < names.size(); ++j) EXPECT_NE(names[i], names[j]);
  EXPECT_EQ(names.front(), "constant") << "the default comes first";
}

}  // namespace density_test
}  // namespace nimbus
