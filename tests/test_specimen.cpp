// Multilayer compaction of a cylindrical specimen, and the exact sphere-slab volumes it is measured with.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>

#include <cmath>

#include "host/triax/specimen.hpp"
#include "test_util.hpp"

using namespace dem;

TEST(Specimen, SphereSlabVolumeIsExact) {
  const double r = 1e-3, full = 4.0 / 3.0 * M_PI * r * r * r;
  EXPECT_NEAR(sphere_slab_volume(0, r, -2 * r, 2 * r), full, 1e-15 * full);
  EXPECT_NEAR(sphere_slab_volume(0, r, 0, 2 * r), full / 2, 1e-15 * full);
  // A slab of thickness r/2 through the centre: pi (r^2 t - t^3 / 12) with t = r / 2.
  const double t = r / 2;
  EXPECT_NEAR(sphere_slab_volume(0, r, -t / 2, t / 2), M_PI * (r * r * t - t * t * t / 12), 1e-15 * full);
  EXPECT_EQ(sphere_slab_volume(0, r, 2 * r, 3 * r), 0.0);
}

TEST(Specimen, CacheRoundTripsBitForBitAndRefusesOtherKeys) {
  Specimen sp;
  sp.height = 12e-3;
  sp.void_ratio = 0.7123456789012345;
  sp.layers.push_back({0, 6e-3, 6.1e-3, 0.69, 1234, 8.5e-4});
  sp.porosity_profile = {0.41, 0.40};
  BallSpec b;
  b.x = Vec3(1.0 / 3.0 * 1e-3, -2.0 / 7.0 * 1e-3, 5e-3);
  b.radius = 1e-3;
  b.density = 2500;
  sp.balls = {b, b};
  sp.balls[1].x.z = 7.123456789e-3;
  const auto dir = dem::test::scratch_dir("specimen");
  const std::string path = (dir / "s.csv").string();
  save_specimen(path, sp, "key A");
  Specimen back;
  EXPECT_FALSE(load_specimen(path, "key B", back));  // built for other settings: not reused
  ASSERT_TRUE(load_specimen(path, "key A", back));
  ASSERT_EQ(back.balls.size(), 2u);
  EXPECT_EQ(back.balls[0].x.x, sp.balls[0].x.x);  // 17 digits: the same double
  EXPECT_EQ(back.balls[1].x.z, sp.balls[1].x.z);
  EXPECT_EQ(back.void_ratio, sp.void_ratio);
  ASSERT_EQ(back.layers.size(), 1u);
  EXPECT_EQ(back.layers[0].steps, 1234);
  EXPECT_EQ(back.porosity_profile.size(), 2u);
  std::ofstream(dir / "bad.csv") << "# key key A\n# height_m 0.012 void_ratio 0.7\nx_m,y_m,z_m,radius_m,density_kg_m3\n1,2\n";
  try {
    load_specimen((dir / "bad.csv").string(), "key A", back);
    FAIL() << "a truncated row must be refused";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:4"), std::string::npos) << e.what();
  }
  // A file cut at a line's end parses whole: the key's ball count refuses it (a specimen of 292 balls was used where
  // the key said 452, issue 65).
  save_specimen(path, sp, "v2 d 0.002 n 3 layers 1");
  try {
    load_specimen(path, "v2 d 0.002 n 3 layers 1", back);
    FAIL() << "a specimen with fewer balls than its key says must be refused";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("damaged specimen file (2 balls where its key says 3); delete it"),
              std::string::npos) << e.what();
  }
  // Sealed: a ball moved by an edit (issue 65: one ball 0.5 m away blew the run up, blamed on the walls) is refused,
  // a line added below the seal too; a file without its checksum line (cut short) is not used but built again.
  save_specimen(path, sp, "key A");
  const auto edited = [&](const std::function<std::string(std::string)>& edit) {
    std::ifstream in(path);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream((dir / "edited.csv").string()) << edit(text);
    return (dir / "edited.csv").string();
  };
  const auto refusal = [&](const std::string& file) -> std::string {
    try {
      load_specimen(file, "key A", back);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_NE(refusal(edited([](std::string t) { return t.replace(t.find("0.0050000000000000001"), 3, "0.5"); })).find(
                "edited or damaged after triaxdem wrote it"), std::string::npos);
  EXPECT_NE(refusal(edited([](std::string t) { return t + "1,2,3,4,5\n"; })).find("a line below its checksum line"),
            std::string::npos);
  EXPECT_FALSE(load_specimen(edited([](std::string t) { return t.substr(0, t.rfind("# checksum")); }), "key A", back));
  // The test's friction does not enter the key: the nine paper cases share one specimen.
  const Config s1 = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/configs/paper/S1_100kPa.toml");
  const Config s3 = load_config(std::string(TRIAXDEM_SOURCE_DIR) + "/configs/paper/S3_300kPa.toml");
  EXPECT_EQ(specimen_key(s1), specimen_key(s3));
  Config other = s1;
  other.run.seed = 2;
  EXPECT_NE(specimen_key(s1), specimen_key(other));
  // The law's own keys (model_keys) enter it, for the balls and the walls alike; an extension does not (preparation
  // runs the law without them).
  auto changed = [&](const std::function<void(Config&)>& edit) {
    Config c = s1;
    edit(c);
    return specimen_key(c) != specimen_key(s1);
  };
  EXPECT_TRUE(changed([](Config& c) { c.ball.emod *= 1.1; }));
  EXPECT_TRUE(changed([](Config& c) { c.wall.kratio *= 1.1; }));
  EXPECT_TRUE(changed([](Config& c) { c.ball.beta_n = 0.1; }));
  EXPECT_FALSE(changed([](Config& c) { c.ball.hertz_overlap = 3e-3; }));
}

TEST(Specimen, SmallSpecimenReachesTheTargetVoidRatio) {
  // 12 mm x 12 mm, 2 mm beads, 3 layers, e = 0.80: 180 beads. The ball count is set from the target,
  // and the last platen stroke ends at the full height, so the whole specimen lands on the target up to
  // the beads that bulge over the top and bottom (their caps are cut by the slab): 0.01 as the issue asks.
  // Friction while settling (0.15, the beads' own): without it the pressed layers creep, and how long a
  // frictionless layer takes to come to rest depends on the last bits of the arithmetic (layer 3 of the
  // sanitizer build was still at an unbalanced ratio of 9.5e-3 after the 200,000-step cap; the release
  // build's stopped well before it). The next test checks that the settling friction keeps e.
  Config c = test::specimen_config(12e-3, 0.80, 3);
  c.solver.gravity = {0, 0, -9.81};
  c.ball.mu_s = 0.15;
  c.ball.mu_r = 0.015;
  c.wall = c.ball;
  c.specimen.settle_mu_s = 0.15;
  const Specimen s = build_specimen(c, false);
  EXPECT_EQ(static_cast<long>(s.balls.size()), specimen_ball_count(c));
  EXPECT_NEAR(s.height, 12e-3, 1e-9);  // the last platen reached the target height
  EXPECT_NEAR(s.void_ratio, 0.80, 0.01);
  ASSERT_EQ(s.layers.size(), 3u);
  for (const LayerReport& l : s.layers) {
    EXPECT_TRUE(std::isfinite(l.void_ratio));
    EXPECT_LT(l.unbalanced, 1e-3);
  }
  for (const BallSpec& b : s.balls) {
    EXPECT_LE(std::hypot(b.x.x, b.x.y), 6e-3 - b.radius + 0.1 * b.radius);  // inside the mould
    EXPECT_GE(b.x.z, b.radius * 0.9);
    EXPECT_LE(b.x.z, 12e-3 - b.radius * 0.9);
  }
  EXPECT_EQ(s.porosity_profile.size(), 24u);
}

TEST(Specimen, LowerLayersEndAtTheirOwnStopRatio) {
  // The layers below the top one are pressed again by the next ones: with layer_stop_ratio they end at that ratio,
  // in fewer steps than at stop_ratio (which a lower layer that ignored it would not take), and the top one still
  // ends at stop_ratio; the specimen keeps its void ratio (within 0.01, as the other specimen tests).
  Config c = test::specimen_config(12e-3, 0.75, 2);
  const Specimen strict = build_specimen(c, false);
  c.specimen.layer_stop_ratio = 1e-2;
  const Specimen quick = build_specimen(c, false);
  ASSERT_EQ(quick.layers.size(), 2u);
  EXPECT_LT(quick.layers[0].unbalanced, 1e-2);
  EXPECT_LT(quick.layers[0].steps, strict.layers[0].steps);
  EXPECT_LT(quick.layers[1].unbalanced, c.specimen.stop_ratio);
  EXPECT_NEAR(quick.void_ratio, 0.75, 0.01);
  EXPECT_NE(specimen_key(c), specimen_key(test::specimen_config(12e-3, 0.75, 2))) << "a cached specimen of the "
                                                                                      "other protocol is not reused";
}

TEST(Specimen, FrictionWhileSettlingKeepsTheTargetAndSavesSteps) {
  // Frictionless packings creep: a layer pressed without friction takes long to reach the unbalanced ratio
  // of 1e-3. Friction switched on once the layer is pressed must not change how far it was pressed (e
  // within 0.01 of the target) and must bring it to rest in fewer steps.
  Config c = test::specimen_config(12e-3, 0.75, 2);
  const Specimen plain = build_specimen(c, false);
  c.specimen.settle_mu_s = 0.15;
  const Specimen settled = build_specimen(c, false);
  EXPECT_NEAR(settled.void_ratio, 0.75, 0.01);
  long steps_plain = 0, steps_settled = 0;
  for (const LayerReport& l : plain.layers) steps_plain += l.steps;
  for (const LayerReport& l : settled.layers) steps_settled += l.steps;
  EXPECT_LT(steps_settled, steps_plain) << steps_settled << " against " << steps_plain;
}
