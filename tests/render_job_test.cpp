// The render job of the library (job/render_job.h), driven as an embedding program or a binding
// drives it: the same pixels as render(), progress, cancellation, checkpoints and resuming, the
// memory check, and a checkpoint of another scene refused.

#include "nimbus/job/render_job.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "nimbus/job/fingerprint.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "support/process.h"

namespace nimbus {
namespace render_job_test {

namespace fs = std::filesystem;

constexpr const char* kScene = R"({
  "film": {"width": 20, "height": 12},
  "camera": {"type": "perspective", "from": [0, 1, 6], "to": [0, 0, 0], "fov": 35},
  "integrator": {"spp": 6, "seed": 5},
  "lights": [{"type": "environment", "radiance": [0.8, 0.9, 1.0]}],
  "media": {"fog": {"sigma_a": 0.2, "sigma_s": [3, 4, 5], "density": {"type": "field"}}},
  "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1.5}, "medium": "fog"}]
})";

class Job : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_test_dir("nimbus_job");
    scene_ = (dir_ / "scene.json").string();
    std::ofstream(scene_) << kScene;
  }
  void TearDown() override { fs::remove_all(dir_); }
  Film reference(int spp) const {
    RenderOptions o;
    o.threads = 2;
    return render(compile_scene(load_scene_file(scene_, {fmt::format("integrator.spp={}", spp)})),
                  o)
        .film;
  }
  fs::path dir_;
  std::string scene_;
};

TEST_F(Job, RendersTheBitsOfRenderWithRisingProgress) {
  RenderJobOptions o;
  o.threads = 2;
  std::vector<double> fractions;
  o.progress = [&](double f) { fractions.push_back(f); };
  RenderJob job(o);
  job.prepare(scene_);
  const JobOutcome r = job.run();
  EXPECT_FALSE(r.stopped);
  EXPECT_TRUE(r.film.sum == reference(6).sum);
  ASSERT_FALSE(fractions.empty());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
  EXPECT_EQ(job.stats(r)["settings"]["integrator"]["spp"], 6);
  EXPECT_EQ(job.summary(r).rfind("20x12, 6 spp in ", 0), 0u) << job.summary(r);
}

// Cancelled once some work is done, with a checkpoint: the film holds whole units, the checkpoint
// is saved, and a second job continues it to the pixels of one uninterrupted render.
TEST_F(Job, CancelledCheckpointedAndResumedIsTheUninterruptedRender) {
  const std::string ck = (dir_ / "ck.nck").string();
  RenderJobOptions o;
  o.threads = 1;
  o.spp = 200;
  o.checkpoint = ck;
  o.checkpoint_interval = 0.01;
  // Stopped once the first checkpoint is saved (the render takes some 100 times as long).
  o.cancel = [&] { return fs::exists(ck); };
  RenderJob first(o);
  first.prepare(scene_);
  const JobOutcome a = first.run();
  ASSERT_TRUE(a.stopped);
  EXPECT_TRUE(a.checkpoint_failure.empty()) << a.checkpoint_failure;
  const uint64_t held = samples_held(a.film);
  EXPECT_GT(held, 0u);
  EXPECT_LT(held, uint64_t(20 * 12 * 200));
  EXPECT_EQ(samples_held(load_checkpoint(ck).film), held);

  RenderJobOptions r;
  r.threads = 2;
  r.resume = ck;
  RenderJob second(r);
  second.prepare(scene_);
  const JobOutcome b = second.run();
  EXPECT_FALSE(b.stopped);
  EXPECT_EQ(b.samples_at_start, held);
  EXPECT_TRUE(b.film.sum == reference(200).sum);
  EXPECT_EQ(second.stats(b)["checkpoint"]["samples"], 20 * 12 * 200);
}

TEST_F(Job, RefusesACheckpointOfOtherSettingsAndTooLittleMemory) {
  const std::string ck = (dir_ / "ck.nck").string();
  RenderJobOptions o;
  o.checkpoint = ck;
  o.spp = 2;
  RenderJob first(o);
  first.prepare(scene_);
  first.run();

  RenderJobOptions r;
  r.resume = ck;
  r.seed = 9;
  RenderJob other(r);
  try {
    other.prepare(scene_);
    ADD_FAILURE() << "a checkpoint of another seed was accepted";
  } catch (const JobError& e) {
    EXPECT_EQ(std::string(e.what()), "--resume " + ck +
                                         ": the checkpoint is of another scene or other settings "
                                         "(scene.integrator.seed: 5 in the checkpoint, 9 now)");
  }
  RenderJobOptions m;
  m.max_memory = 1 << 20;
  RenderJob small(m);
  try {
    small.prepare(scene_);
    ADD_FAILURE() << "a render above max_memory was accepted";
  } catch (const JobError& e) {
    EXPECT_NE(std::string(e.what()).find("more than the 1.0 MiB allowed by --max-memory"),
              std::string::npos)
        << e.what();
  }
}

// A scene built in code: its identity stands for its description in the checkpoint.
TEST_F(Job, ASceneBuiltInCodeResumesUnderItsIdentity) {
  const Scene scene = compile_scene(load_scene_file(scene_));
  const std::string ck = (dir_ / "code.nck").string();
  RenderJobOptions o;
  o.spp = 3;
  o.checkpoint = ck;
  RenderJob first(o);
  first.set_scene(scene, {{"name", "fog"}});
  first.run();
  RenderJobOptions r;
  r.resume = ck;
  r.spp = 6;
  RenderJob same(r);
  same.set_scene(scene, {{"name", "fog"}});
  EXPECT_TRUE(same.run().film.sum == reference(6).sum);
  RenderJob other(r);
  EXPECT_THROW(other.set_scene(scene, {{"name", "smoke"}}), JobError);
  RenderJobOptions seeded;
  seeded.seed = 1;
  RenderJob refused(seeded);
  EXPECT_THROW(refused.set_scene(scene, {}), std::invalid_argument);
}

// To a noise target (render/noise_target.h): the job's passes, its work units with checkpoints,
// and a checkpoint stopped part way and resumed on other threads, all give the same blocks at the
// same counts with the same bits; the progress rises to 1 and the pixels done reach all.
TEST_F(Job, ToANoiseTargetTheSameBitsInPassesInUnitsAndResumed) {
  const std::vector<std::string> target = {"integrator.noise_target=0.04", "film.width=40",
                                           "film.height=24"};
  RenderJobOptions o;
  o.overrides = target;
  o.threads = 2;
  o.spp = 600;
  std::vector<double> fractions;
  double converged = 0;
  o.progress = [&](double f) { fractions.push_back(f); };
  o.noise_progress = [&](const NoiseProgress& p) { converged = p.converged; };
  RenderJob passes(o);
  passes.prepare(scene_);
  const JobOutcome a = passes.run();
  ASSERT_FALSE(a.stopped);
  const auto [least, most] = std::minmax_element(a.film.samples.begin(), a.film.samples.end());
  EXPECT_EQ(*least, 16u);
  EXPECT_GT(*most, 100u);
  EXPECT_LT(samples_held(a.film), uint64_t(40 * 24 * 600) / 2);
  ASSERT_FALSE(fractions.empty());
  EXPECT_EQ(fractions.back(), 1.0);
  EXPECT_EQ(converged, 1.0);
  EXPECT_EQ(passes.stats(a)["noise_target"]["pixels_done"], 1.0);
  // The most a pixel took, then the cap it was allowed.
  EXPECT_NE(passes.summary(a).find(fmt::format("noise target 0.04: {:.1f} spp on average, {} at "
                                               "most (cap 600), ",
                                               double(samples_held(a.film)) / (40 * 24), *most)),
            std::string::npos)
      << passes.summary(a);

  const std::string ck = (dir_ / "noise.nck").string();
  RenderJobOptions c = o;
  c.threads = 1;
  c.checkpoint = ck;
  c.checkpoint_interval = 0.01;
  c.progress = {};
  c.cancel = [&] { return fs::exists(ck); };
  RenderJob first(c);
  first.prepare(scene_);
  const JobOutcome stopped = first.run();
  ASSERT_TRUE(stopped.stopped);
  EXPECT_LT(samples_held(stopped.film), samples_held(a.film));

  RenderJobOptions r;
  r.overrides = target;
  r.threads = 2;
  r.resume = ck;
  RenderJob second(r);
  second.prepare(scene_);
  const JobOutcome b = second.run();
  EXPECT_FALSE(b.stopped);
  EXPECT_EQ(b.film.samples, a.film.samples);
  EXPECT_TRUE(b.film.sum == a.film.sum);

  // Resumed to another target: the checkpoint is of other settings.
  r.overrides[0] = "integrator.noise_target=0.02";
  RenderJob other(r);
  EXPECT_THROW(other.prepare(scene_), JobError);
}

}  // namespace render_job_test
}  // namespace nimbus
