// The pieces of a render job (src/nimbus/job/): film patches, the work queue's lanes and order,
// checkpoint files and the fingerprint that a resumed render must match.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "nimbus/job/checkpoint.h"
#include "nimbus/job/film_patch.h"
#include "nimbus/job/fingerprint.h"
#include "nimbus/job/shared_render.h"
#include "nimbus/job/work_queue.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace nimbus {
namespace job_test {

Film numbered_film(int w, int h) {
  Film f(w, h);
  for (int p = 0; p < f.pixels(); ++p) {
    f.add(p, Rgb({0.25 * p, 1.0 / (p + 1), -3.0 * p}));
    f.add(p, Rgb({1e-7 * p, 2.0, 0.5}));
  }
  return f;
}

TEST(FilmPatch, TakenPackedUnpackedAndMergedGivesTheFilmBack) {
  Film film = numbered_film(7, 5);
  const Film original = film;
  const PixelRect rect{2, 1, 6, 4};
  const FilmPatch taken = take_patch(film, rect);
  EXPECT_EQ(film.samples[1 * 7 + 2], 0u);
  EXPECT_EQ(film.samples[0], 2u);
  const FilmPatch back = unpack_patch(pack_patch(taken));
  merge_patch(film, back);
  EXPECT_EQ(film.samples, original.samples);
  EXPECT_EQ(film.sum, original.sum);
  for (int p = 0; p < film.pixels(); ++p)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(film.sum_sq[p][c], original.sum_sq[p][c]);
  std::vector<std::byte> cut = pack_patch(taken);
  cut.pop_back();
  EXPECT_THROW(unpack_patch(cut), std::runtime_error);
}

TEST(WorkQueue, LanesAreBandsSplitWhereCountsDiffer) {
  Film film(10, 6);
  EXPECT_EQ(lanes_of(film, 4).size(), 2u);
  film.samples[5 * 10 + 3] = 8;  // band 2, row 5: runs [0, 3), [3, 4), [4, 10); row 4: one run
  const std::vector<PixelRect> lanes = lanes_of(film, 4);
  ASSERT_EQ(lanes.size(), 5u);
  EXPECT_EQ(lanes[0].y1, 4);
  EXPECT_EQ(lanes[1].y0, 4);
  EXPECT_EQ(lanes[1].x1, 10);
  EXPECT_EQ(lanes[3].x0, 3);
  EXPECT_EQ(lanes[3].x1, 4);
}

// Units come lane by lane in sample order, the least advanced lane first, and the film then
// holds every sample once: here each "render" adds one sample of value s to each pixel.
TEST(WorkQueue, HandsOutEverySampleOnceInOrderPerLane) {
  const int spp = 7;
  WorkQueue queue(Film(9, 10), spp, 3, 2, 0.001);
  std::vector<int> next_sample(4, 0);
  int units = 0, rank = 0;
  while (const auto u = queue.try_next()) {
    EXPECT_EQ(u->s0, next_sample.at(u->lane));
    next_sample[u->lane] = u->s1;
    Film scratch(9, 10);
    for (int y = u->rect.y0; y < u->rect.y1; ++y)
      for (int x = u->rect.x0; x < u->rect.x1; ++x)
        for (int s = u->s0; s < u->s1; ++s) scratch.add(y * 9 + x, Rgb(double(s)));
    queue.complete(rank, *u, take_patch(scratch, u->rect), 1e-4 * (u->s1 - u->s0), {});
    rank = 1 - rank;
    ++units;
  }
  EXPECT_TRUE(queue.finished());
  EXPECT_DOUBLE_EQ(queue.fraction_done(), 1.0);
  const Film film = queue.film();
  for (int p = 0; p < film.pixels(); ++p) {
    EXPECT_EQ(film.samples[p], uint32_t(spp));
    EXPECT_EQ(film.mean(p)[0], 3.0);  // (0 + ... + 6) / 7
  }
  const std::vector<uint64_t> per_rank = queue.samples_per_rank();
  EXPECT_EQ(per_rank[0] + per_rank[1], uint64_t(9 * 10 * spp));
  EXPECT_GT(units, 4);  // lanes' first units are one sample
  EXPECT_THROW(WorkQueue(film, spp - 1, 3, 1, 1), std::invalid_argument);
}

// One lane (a dense region) keeps several units out at once; a result that comes before an
// earlier one of its lane waits for it, and a unit given back is handed out again.
TEST(WorkQueue, UnitsOfOneLaneMayBeOutTogetherAndComeBackInAnyOrder) {
  WorkQueue queue(Film(4, 4), 3, 4, 2, 1);
  auto unit_film = [](const WorkUnit& u) {
    Film f(4, 4);
    for (int p = 0; p < 16; ++p)
      for (int s = u.s0; s < u.s1; ++s) f.add(p, Rgb(double(1 << s)));
    return take_patch(f, u.rect);
  };
  const auto a = queue.try_next(), b = queue.try_next(), c = queue.try_next();
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(a->s0, 0);
  EXPECT_EQ(b->s0, 1);
  EXPECT_EQ(c->s0, 2);
  EXPECT_FALSE(queue.try_next());  // every sample is out
  queue.complete(1, *c, unit_film(*c), 0.1, {});
  queue.complete(0, *b, unit_film(*b), 0.1, {});
  EXPECT_EQ(queue.film().samples[0], 0u);  // samples 1 and 2 wait for sample 0
  EXPECT_THROW(queue.complete(0, *b, unit_film(*b), 0.1, {}), std::invalid_argument);
  queue.abandon(*a);
  const auto again = queue.try_next();
  ASSERT_TRUE(again);
  EXPECT_EQ(again->s0, 0);
  EXPECT_EQ(again->s1, 1);
  EXPECT_FALSE(queue.finished());
  queue.complete(1, *again, unit_film(*again), 0.1, {});
  EXPECT_TRUE(queue.finished());
  const Film film = queue.film();
  EXPECT_EQ(film.samples[5], 3u);
  EXPECT_EQ(film.mean(5)[0], 7.0 / 3);  // (1 + 2 + 4) / 3
}

TEST(WorkQueue, StopEndsTheHandingOut) {
  WorkQueue queue(Film(4, 4), 2, 4, 1, 1);
  const auto u = queue.try_next();
  ASSERT_TRUE(u);
  queue.abandon(*u);
  queue.stop();
  EXPECT_FALSE(queue.try_next());
  EXPECT_FALSE(queue.wait_next());
  EXPECT_FALSE(queue.finished());
  EXPECT_TRUE(queue.none_out());
}

TEST(Checkpoint, SavedAndLoadedBitForBit) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("nimbus_ckpt_" + std::to_string(::getpid())))
          .string();
  Checkpoint c;
  c.fingerprint = {{"scene", {{"film", {{"width", 7}}}}}};
  c.majorants = 0x123456789abcdefull;
  c.spp = 24;
  c.film = numbered_film(7, 5);
  save_checkpoint(c, path);
  const Checkpoint back = load_checkpoint(path);
  EXPECT_EQ(back.fingerprint, c.fingerprint);
  EXPECT_EQ(back.majorants, c.majorants);
  EXPECT_EQ(back.spp, 24);
  EXPECT_EQ(back.film.sum, c.film.sum);
  EXPECT_EQ(back.film.samples, c.film.samples);
  EXPECT_EQ(samples_held(back.film), uint64_t(2 * 35));
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 1);
  EXPECT_THROW(load_checkpoint(path), std::runtime_error);
  std::ofstream(path) << "{\"film\": 1}";
  try {
    load_checkpoint(path);
    ADD_FAILURE() << "a JSON file passed for a checkpoint";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": not a nimbus checkpoint");
  }
  std::filesystem::remove(path);
}

// Issue 29: one byte of a pixel's record flipped was resumed (an image mean of -5e12), a sample
// count set to 0 silently doubled a pixel. Any byte changed, or the file cut short, is refused.
TEST(Checkpoint, ADamagedOrShortenedFileIsRefused) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("nimbus_ckdmg_" + std::to_string(::getpid())))
          .string();
  Checkpoint c;
  c.fingerprint = {{"scene", {{"film", {{"width", 7}}}}}};
  c.spp = 24;
  c.film = numbered_film(7, 5);
  save_checkpoint(c, path);
  std::string good;
  {
    std::ifstream in(path, std::ios::binary);
    good.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string damaged =
      path + ": the checkpoint is damaged or cut short (its checksum does not match)";
  // After the magic and the version: the spp, the fingerprint, the film's pixels (a count, a
  // sum), the checksum itself.
  int refused = 0;
  for (size_t at = 12; at < good.size(); at += 7) {
    for (const unsigned char flip : {0x01, 0x80}) {
      std::string bad = good;
      bad[at] = char(bad[at] ^ flip);
      std::ofstream(path, std::ios::binary | std::ios::trunc) << bad;
      try {
        load_checkpoint(path);
        ADD_FAILURE() << "byte " << at << " changed, and the checkpoint was read";
      } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), damaged) << "byte " << at;
        ++refused;
      }
    }
  }
  EXPECT_GT(refused, 2 * 7 * 5 * 2);  // more than two per pixel record of 76 bytes
  for (const size_t cut : {size_t(1), size_t(4), size_t(80), good.size() - 13}) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << good.substr(0, good.size() - cut);
    EXPECT_THROW(load_checkpoint(path), std::runtime_error) << cut << " bytes cut";
  }
  std::ofstream(path, std::ios::binary | std::ios::trunc) << good;
  EXPECT_EQ(load_checkpoint(path).film.samples, c.film.samples);
  std::filesystem::remove(path);
}

TEST(Fingerprint, NamesTheFirstSettingThatDiffers) {
  const nlohmann::json a = {{"scene", {{"integrator", {{"seed", 1}}}, {"film", {{"width", 8}}}}}};
  nlohmann::json b = a;
  EXPECT_EQ(fingerprint_difference(a, b), "");
  b["scene"]["integrator"]["seed"] = 2;
  EXPECT_EQ(fingerprint_difference(a, b), "scene.integrator.seed: 1 in the checkpoint, 2 now");
  b = a;
  b["scene"]["integrator"]["tracking"] = "delta";
  EXPECT_EQ(fingerprint_difference(a, b),
            "scene.integrator.tracking: absent in the checkpoint, \"delta\" now");
}

// A resumed render must read the same grids: the fingerprint holds their files' hashes.
// The files are those compiling the scene recorded as it read them (issue 25: the fingerprint
// guessed them from the JSON, one level under each medium): a density grid and a temperature grid.
TEST(Fingerprint, HoldsEveryFileTheLoaderRead) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("nimbus_fp_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path vdb = fs::path(NIMBUS_SOURCE_DIR) / "scenes/vdb";
  fs::copy_file(vdb / "vdb_fire.vdb", dir / "fire.vdb");
  fs::copy_file(vdb / "vdb_fire.vdb", dir / "heat.vdb");
  std::ofstream(dir / "scene.json") << R"({"integrator": {"spp": 4, "seed": 2},
    "camera": {"type": "perspective", "from": [0, 0, 5], "to": [0, 0, 0], "fov": 30},
    "media": {"m": {"sigma_a": 1, "density": {"type": "vdb", "file": "fire.vdb"},
                    "emission": {"file": "heat.vdb"}}},
    "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1}, "medium": "m"}]})";
  const std::string scene = (dir / "scene.json").string();
  const auto fingerprint = [&](const std::vector<std::string>& overrides) {
    const SceneDesc desc = load_scene_file(scene, overrides);
    std::vector<InputFile> inputs;
    compile_scene(desc, {}, &inputs);
    return render_fingerprint(desc, inputs);
  };
  const nlohmann::json before = fingerprint({"integrator.spp=8"});
  EXPECT_EQ(before["files"].size(), 2u) << before["files"];
  EXPECT_EQ(fingerprint_difference(before, fingerprint({"integrator.spp=24"})), "");
  EXPECT_NE(fingerprint_difference(before, fingerprint({"integrator.seed=3"})), "");
  // The grid of another scene, with the name this one reads.
  fs::copy_file(vdb / "vdb_cloud.vdb", dir / "fire.vdb", fs::copy_options::overwrite_existing);
  const std::string d = fingerprint_difference(before, fingerprint({}));
  EXPECT_EQ(d, (dir / "fire.vdb").string() +
                   ", named at /media/m/density/file, is not the file the checkpoint's render "
                   "read (its size or content differs)");
  // Size and hash as read, beside the path.
  EXPECT_EQ(before["files"]["/media/m/emission/file"]["bytes"], fs::file_size(dir / "heat.vdb"));
  fs::remove_all(dir);
}

// Issue 44: an exception on the lead's render thread (there from WorkQueue::complete) left its
// unit out for good, and the serving thread waited for it forever. Here the render's cancel poll
// throws, on the render thread alone: the job must end, with that exception.
TEST(SharedRender, AnExceptionOnTheRenderThreadEndsTheJob) {
  const Scene scene = compile_scene(load_scene_text(R"({"film": {"width": 8, "height": 6},
    "camera": {"type": "perspective", "from": [0, 0, 5], "to": [0, 0, 0], "fov": 30},
    "integrator": {"spp": 4},
    "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1}}]})",
                                                    "<tiny>"));
  SharedRenderSettings s;
  s.spp = 4;
  s.threads = 1;  // the render thread polls itself (no other pool thread)
  s.start = make_film(scene);
  const std::thread::id serving = std::this_thread::get_id();
  s.stop = [serving] {
    if (std::this_thread::get_id() != serving)
      throw std::runtime_error("thrown on the render thread");
    return false;
  };
  try {
    lead_shared_render(scene, nullptr, std::move(s));
    FAIL() << "the job ended without the exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "thrown on the render thread");
  }
}

}  // namespace job_test
}  // namespace nimbus
