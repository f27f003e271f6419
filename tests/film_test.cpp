// The mergeable film and the render over a range of pixels and samples (issue 12): however the
// pixels are split, and whenever samples continue in order, the film is the same bits as one
// render; films round-trip through files; bad ranges and bad files are refused with one line.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "nimbus/frep/primitives.h"
#include "nimbus/io/film_file.h"
#include "nimbus/media/cloud_density.h"
#include "nimbus/render/memory_estimate.h"
#include "nimbus/render/renderer.h"
#include "support/scene_builders.h"

namespace nimbus {
namespace film_test {

// A cloud in a sphere under a sun and a sky: media, shadow rays and surfaces-free paths.
Scene small_scene(int spp) {
  Scene scene;
  scene.settings = {37,
                    23,
                    spp,
                    9,
                    100,
                    test::tracking_settings(TrackingSettings::Mode::SpectralMis,
                                            TrackingSettings::Absorption::Collide, false, 4),
                    {}};
  scene.camera = perspective_camera({0, 0.5, 3.2}, {0, 0, 0}, {0, 1, 0}, 45, 37, 23);
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = normalize(Vec3{-0.4, -1, -0.3});
  sun.emission = Rgb(3.0);
  scene.lights.push_back(sun);
  scene.lights.push_back(test::environment(0.3));
  Medium cloud;
  cloud.sigma_s = Rgb({4.0, 6.0, 8.0});
  cloud.sigma_a = Rgb(0.2);
  cloud.density = make_cloud_density(CloudParams{});
  scene.media.push_back(cloud);
  scene.objects.push_back(
      test::object_of(make_shape(QuadricNode{sphere({0, 0, 0}, 1)}), Surface::Type::None, 0));
  test::finish_media(scene);
  return scene;
}

void expect_same_bits(const Film& a, const Film& b) {
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  ASSERT_EQ(a.exponent, b.exponent);
  for (int p = 0; p < a.pixels(); ++p) {
    ASSERT_EQ(a.samples[p], b.samples[p]) << p;
    ASSERT_TRUE(a.sum[p] == b.sum[p]) << p;
    ASSERT_TRUE(a.sum_sq[p] == b.sum_sq[p]) << p;
  }
}

RenderOptions range(int x0, int y0, int x1, int y1, int s0, int s1, int threads = 0) {
  RenderOptions o;
  o.threads = threads;
  o.range = {x0, y0, x1, y1, s0, s1};
  return o;
}

TEST(Film, PixelSplitsAndSampleContinuationsGiveTheSameBits) {
  const Scene scene = small_scene(6);
  const Film whole = render(scene).film;
  for (int p = 0; p < whole.pixels(); ++p) ASSERT_EQ(whole.samples[p], 6u);

  // Four uneven pixel blocks into one film, on different thread counts.
  Film blocks(37, 23);
  render_into(scene, blocks, range(0, 0, 20, 11, 0, -1, 1));
  render_into(scene, blocks, range(20, 0, 37, 11, 0, -1, 2));
  render_into(scene, blocks, range(0, 11, 5, 23, 0, -1, 2));
  render_into(scene, blocks, range(5, 11, 37, 23, 0, -1, 1));
  expect_same_bits(whole, blocks);

  // Samples [0, 2), then [2, 6), into the same film.
  Film continued(37, 23);
  render_into(scene, continued, range(0, 0, -1, -1, 0, 2));
  render_into(scene, continued, range(0, 0, -1, -1, 2, 6));
  expect_same_bits(whole, continued);

  // Disjoint pixel blocks in separate films (separate processes), merged.
  Film left(37, 23), right(37, 23), merged(37, 23);
  render_into(scene, left, range(0, 0, 18, 23, 0, -1));
  render_into(scene, right, range(18, 0, 37, 23, 0, -1));
  merge(merged, right);
  merge(merged, left);
  expect_same_bits(whole, merged);
}

// Issue 12: the samples of one pixel split between films (processes) and merged in any order
// give the same pixels, to the bit, as one render: the sums are exact.
TEST(Film, SampleSplitsMergedInAnyOrderGiveTheSameBits) {
  const Scene scene = small_scene(6);
  const Film whole = render(scene).film;
  Film a(37, 23), b(37, 23), c(37, 23);
  render_into(scene, a, range(0, 0, -1, -1, 0, 1));
  render_into(scene, b, range(0, 0, -1, -1, 1, 4, 1));
  render_into(scene, c, range(0, 0, -1, -1, 4, 6, 2));
  Film cba = c, acb = a;
  merge(cba, b);
  merge(cba, a);
  merge(acb, c);
  merge(acb, b);
  for (const Film* m : {&cba, &acb})
    for (int p = 0; p < whole.pixels(); ++p) {
      ASSERT_EQ(m->samples[p], 6u);
      ASSERT_TRUE(m->sum[p] == whole.sum[p]) << p;
      ASSERT_TRUE(m->mean(p) == whole.mean(p)) << p;
      // Sums of squares (error estimates only) agree to rounding.
      for (int k = 0; k < 3; ++k)
        ASSERT_NEAR(m->sum_sq[p][k], whole.sum_sq[p][k], 1e-12 * (1 + whole.sum_sq[p][k])) << p;
    }
  // The exact sums do not depend on the order of addition; doubles would have (checked on this
  // scene: summing the three parts' double sums in the two orders differs in some pixel).
  bool doubles_differ = false;
  for (int p = 0; p < whole.pixels(); ++p) {
    const Rgb x = (c.sum[p].value() + b.sum[p].value()) + a.sum[p].value();
    const Rgb y = (a.sum[p].value() + c.sum[p].value()) + b.sum[p].value();
    doubles_differ = doubles_differ || !(x == y);
  }
  EXPECT_TRUE(doubles_differ);
  EXPECT_THROW(merge(cba, Film(36, 23)), std::invalid_argument);
}

TEST(Film, RangesThatDoNotContinueAreRefused) {
  const Scene scene = small_scene(4);
  Film film(37, 23);
  auto message = [&](const RenderOptions& o, Film& f) {
    try {
      render_into(scene, f, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  Film three(37, 23);
  render_into(scene, three, range(0, 0, -1, -1, 0, 3));
  EXPECT_EQ(message(range(0, 0, -1, -1, 2, 4), three),
            "pixel (0, 0) holds 3 samples; samples [2, 4) continue from 2");
  Film wrong(10, 10);
  EXPECT_EQ(message({}, wrong), "the film is 10x10 pixels, the scene's image 37x23");
  EXPECT_EQ(message(range(0, 0, 38, 5, 0, -1), film),
            "pixels [0, 38) x [0, 5) are not within 37x23");
  EXPECT_EQ(message(range(0, 0, -1, -1, 3, 2), film), "samples [3, 2) are not a range");
  for (int p = 0; p < film.pixels(); ++p) EXPECT_EQ(film.samples[p], 0u) << "nothing rendered";
}

TEST(Film, CancelledRendersLeaveWholePixelsOnly) {
  const Scene scene = small_scene(4);
  Film film(37, 23);
  std::atomic<int> polls{0};
  RenderOptions o = range(0, 0, -1, -1, 0, -1, 1);
  o.cancel = [&] { return ++polls > 300; };  // 300 pixels, then stop
  const RenderStats s = render_into(scene, film, o);
  EXPECT_TRUE(s.cancelled);
  int done = 0;
  for (int p = 0; p < film.pixels(); ++p) {
    EXPECT_TRUE(film.samples[p] == 0 || film.samples[p] == 4) << p;
    done += film.samples[p] == 4;
  }
  EXPECT_EQ(done, 300);
  // The rest can be rendered later, pixel by pixel, and the film is then one render's bits.
  for (int p = 0; p < film.pixels(); ++p) {
    if (film.samples[p] != 0) continue;
    const RenderStats rest =
        render_into(scene, film, range(p % 37, p / 37, p % 37 + 1, p / 37 + 1, 0, -1));
    EXPECT_FALSE(rest.cancelled);
  }
  expect_same_bits(render(scene).film, film);
}

// Issue 44: two threads rendering into one film at once both returned, and one's samples were
// lost. The second is refused while the first holds the film; the first completes.
TEST(Film, TakesOneRenderAtATime) {
  const Scene scene = small_scene(2);
  Film film(37, 23);
  std::promise<void> claimed, refused;
  std::shared_future<void> second_refused = refused.get_future().share();
  std::once_flag first_poll;
  RenderOptions first = range(0, 0, -1, -1, 0, 2, 1);
  first.cancel = [&] {  // polled once the film is claimed: waits for the second to be refused
    std::call_once(first_poll, [&] { claimed.set_value(); });
    second_refused.wait();
    return false;
  };
  std::thread render_first([&] { render_into(scene, film, first); });
  claimed.get_future().wait();
  try {
    render_into(scene, film, range(0, 0, -1, -1, 0, 1));
    ADD_FAILURE() << "a second render into a film in use was let through";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "the film is already being rendered into (on another thread): wait for that to "
                 "end, or use another film");
  }
  refused.set_value();
  render_first.join();
  expect_same_bits(render(scene).film, film);
  // Free again; a copy of a film in use is free.
  EXPECT_NO_THROW(render_into(scene, film, range(0, 0, -1, -1, 2, 3)));
  const FilmClaim held(film);
  Film copy = film;
  EXPECT_NO_THROW(render_into(scene, copy, range(0, 0, -1, -1, 3, 4)));
}

// Issue 16: a NaN, an infinity or a value whose square overflows never enters the sums; it
// counts as a sample of value 0. Negative values (signed weights) are samples like any other.
TEST(Film, RefusesValuesThatWouldPoisonThePixel) {
  Film film(2, 1);
  EXPECT_TRUE(film.add(0, Rgb({1.0, -2.0, 3.0})));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const Rgb& bad : {Rgb({nan, 0.0, 0.0}), Rgb({0.0, inf, 0.0}), Rgb({0.0, 0.0, -inf}),
                         Rgb({1e200, 1.0, 1.0}), Rgb({1.0, -5e18, 1.0})})
    EXPECT_FALSE(film.add(0, bad));
  EXPECT_EQ(film.samples[0], 6u);
  EXPECT_EQ(film.sum[0].value(), Rgb({1.0, -2.0, 3.0}));
  EXPECT_EQ(film.sum_sq[0], Rgb({1.0, 4.0, 9.0}));
  EXPECT_EQ(film.mean(0), Rgb({1.0 / 6, -2.0 / 6, 3.0 / 6}));
  EXPECT_EQ(film.samples[1], 0u);
}

// Issue 29: the film's range was absolute, so an environment of radiance 1e19 rendered black
// (every sample "NaN or infinite") and one of 1e-20 rendered 0. The exponent follows the
// brightest emitter.
TEST(Film, TheExponentFollowsTheBrightestEmitter) {
  EXPECT_EQ(film_exponent(0), 0);
  EXPECT_EQ(film_exponent(1), 0);
  EXPECT_EQ(film_exponent(0x1p-44), 0);
  EXPECT_EQ(film_exponent(0x1.fp22), 0);
  EXPECT_EQ(film_exponent(0x1p23), 1);
  EXPECT_EQ(film_exponent(1e19), 63 - 22);
  EXPECT_EQ(film_exponent(1e-20), -67 - 22);
  Scene scene = small_scene(1);
  // The sun's irradiance 3, or its D65-shaped curve's largest bin for spectral mode.
  EXPECT_GE(brightest_emission(scene), 3.0);
  EXPECT_LT(brightest_emission(scene), 4.0);
  EXPECT_EQ(scene.film_exponent, 0);
  scene.lights[1].emission = Rgb({0.1, 5e29, 0.1});
  EXPECT_EQ(brightest_emission(scene), 5e29);
}

// The same scene lit 2^64 (1.8e19), 2^-67 (6.8e-21) or 2^99 (6.3e29) times as brightly renders
// the same image times that factor (a power of two, so every path makes the same choices):
// equal to the film's rounding, with no sample refused.
TEST(Film, ScenesLitAtAnyScaleRenderAlike) {
  const Scene reference_scene = small_scene(2);
  const Film reference = render(reference_scene).film;
  for (const double k : {0x1p64, 0x1p-67, 0x1p99}) {
    Scene scene = small_scene(2);
    for (Light& light : scene.lights) light.emission = Rgb(light.emission.rgb * k);
    test::finish_media(scene);
    EXPECT_NE(scene.film_exponent, 0) << k;
    const RenderResult r = render(scene);
    EXPECT_EQ(r.counters.rejected_samples, 0u) << k;
    EXPECT_EQ(r.film.exponent, scene.film_exponent);
    for (int p = 0; p < r.film.pixels(); ++p)
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(r.film.mean(p)[c] / k, reference.mean(p)[c],
                    1e-12 * std::abs(reference.mean(p)[c]) + 0x1p-60)
            << k << " pixel " << p << " channel " << c;
    // A film of another exponent is not this scene's.
    Film other(scene.settings.width, scene.settings.height);
    EXPECT_THROW(render_into(scene, other), std::invalid_argument);
    // Saved and loaded, the exponent comes back.
    const std::string path =
        (std::filesystem::temp_directory_path() / "nimbus_film_exponent.film").string();
    save_film(r.film, path);
    expect_same_bits(r.film, load_film(path));
  }
}

TEST(MemoryEstimate, CountsTheFilmAndParsesSizes) {
  const MemoryEstimate e = estimate_render_memory(100, 50, 2, 3, 4, 0);
  EXPECT_EQ(e.film, 100.0 * 50 * (3 * 16 + 3 * sizeof(double) + sizeof(uint32_t)));
  EXPECT_EQ(e.image, 2 * 100.0 * 50 * 3 * sizeof(float));
  EXPECT_GT(e.octrees, 0);
  EXPECT_EQ(e.media_lists, 0);  // no index-matched media
  EXPECT_EQ(e.total(), e.film + e.image + e.octrees + e.media_lists + e.threads);
  EXPECT_EQ(parse_memory_size("512"), 512u);
  EXPECT_EQ(parse_memory_size("2K"), 2048u);
  EXPECT_EQ(parse_memory_size("1.5G"), 1536ull << 20);
  EXPECT_EQ(parse_memory_size("1T"), 1ull << 40);
  EXPECT_THROW(parse_memory_size("-1G"), std::invalid_argument);
  EXPECT_THROW(parse_memory_size("lots"), std::invalid_argument);
  // Issue 29: std::stod alone read "0x10" as 16 bytes; decimal digits only.
  for (const char* bad : {"0x10", "", "inf", "nan", "1e3", ".5", " 5G"})
    EXPECT_THROW(parse_memory_size(bad), std::invalid_argument) << '"' << bad << '"';
  EXPECT_EQ(format_memory(3.0 * (1 << 30)), "3.0 GiB");
  EXPECT_EQ(format_memory(512.0 * (1 << 20)), "512.0 MiB");
}

TEST(Film, RoundTripsThroughAFile) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "nimbus_film_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "a.film").string();
  Film film = render(small_scene(3)).film;
  film.samples[5] = 0;  // counts per pixel survive too
  save_film(film, path);
  expect_same_bits(film, load_film(path));

  auto message = [&](const std::string& p) {
    try {
      load_film(p);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message((dir / "missing.film").string()),
            (dir / "missing.film").string() + ": cannot open file (No such file or directory)");
  const std::string bad = (dir / "bad.film").string();
  std::ofstream(bad) << "{\"not\": \"a film\"}";
  EXPECT_EQ(message(bad), bad + ": not a nimbus film file");
  const auto size = std::filesystem::file_size(path);
  std::filesystem::copy_file(path, bad, std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(bad, size - 1);
  EXPECT_EQ(message(bad), bad +
                              ": the film file is damaged or cut short (its header claims 37x23 "
                              "pixels, 64676 bytes, and 64675 follow)");
  std::filesystem::copy_file(path, bad, std::filesystem::copy_options::overwrite_existing);
  std::ofstream(bad, std::ios::app) << 'x';
  EXPECT_EQ(message(bad), bad + ": trailing bytes after the film");
  std::filesystem::copy_file(path, bad, std::filesystem::copy_options::overwrite_existing);
  {
    std::fstream f(bad, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(8);
    const uint32_t version = 99;
    f.write(reinterpret_cast<const char*>(&version), sizeof version);
  }
  EXPECT_EQ(message(bad), bad + ": film file version 99, this nimbus reads 4");
  std::filesystem::remove_all(dir);
}

}  // namespace film_test
}  // namespace nimbus
