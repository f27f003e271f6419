// nimbus._core, the compiled part of the Python package nimbus (python/nimbus/__init__.py, which
// checks the arguments and documents the API): scenes loaded as the command line loads them,
// rendered by the same RenderJob into the pixels `nimbus render` writes, with the GIL released
// while rendering and SIGINT turned into KeyboardInterrupt. Paths are taken as Python's own
// functions take them, and outputs follow the command line's rules (io/output.h).

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <functional>
#include <future>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "nimbus/experiments/experiment.h"
#include "nimbus/frep/intersect.h"
#include "nimbus/frep/tape.h"
#include "nimbus/io/exr.h"
#include "nimbus/io/film_file.h"
#include "nimbus/io/film_image.h"
#include "nimbus/io/output.h"
#include "nimbus/job/render_job.h"
#include "nimbus/media/medium_field.h"
#include "nimbus/mesh/polygonize.h"
#include "nimbus/render/memory_estimate.h"
#include "nimbus/render/renderer.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"

namespace py = pybind11;

namespace nimbus_python {

using namespace nimbus;

// A path argument as open() takes one: a str, bytes or os.PathLike, encoded as the file system
// wants; a NUL in it, at which the C library would cut the path short (issue 44: "scene.json\0junk"
// loaded scene.json), is Python's "ValueError: embedded null byte".
std::string path_of(const py::handle& arg) {
  PyObject* bytes = nullptr;
  if (PyUnicode_FSConverter(arg.ptr(), &bytes) == 0) throw py::error_already_set();
  std::string path(PyBytes_AS_STRING(bytes), size_t(PyBytes_GET_SIZE(bytes)));
  Py_DECREF(bytes);
  return path;
}

// Calls f, whose std::runtime_error is a file that cannot be read or written: Python's OSError,
// with the command line's line. The scene's and the job's errors keep their types.
template <class F>
auto os_errors(F&& f) {
  try {
    return f();
  } catch (const SceneError&) {
    throw;
  } catch (const JobError&) {
    throw;
  } catch (const std::runtime_error& e) {
    PyErr_SetString(PyExc_OSError, e.what());
    throw py::error_already_set();
  }
}

// The files that the scenes loaded in this process read: their scene files, instances files and,
// once compiled, grids, as absolute paths. write_image and Film.save never replace one, as
// `nimbus render` never replaces a file it reads. Kept for the process's life (a dropped scene's
// file is often rendered again), one entry per path; used with the GIL held.
std::vector<NamedFile>& files_read() {
  static std::vector<NamedFile> files;
  return files;
}

void remember_read(const std::vector<NamedFile>& read) {
  std::vector<NamedFile>& files = files_read();
  for (const NamedFile& f : read) {
    std::error_code ec;
    const std::filesystem::path absolute = std::filesystem::absolute(f.path, ec);
    const std::string path = ec ? f.path : absolute.string();
    if (std::none_of(files.begin(), files.end(),
                     [&](const NamedFile& g) { return g.path == path; }))
      files.push_back({f.what, path});
  }
}

void remember_inputs(const std::vector<InputFile>& inputs) {
  std::vector<NamedFile> read;
  for (const InputFile& f : inputs) read.push_back({"the file of " + f.pointer, f.path});
  remember_read(read);
}

// ValueError unless `path` may be written by `what` ("write_image"): the checks of
// `nimbus render -o` (check_output_path for an image, else check_writable_path: the folder is
// there and writable, not /dev, /proc or /sys, the path no directory, device or FIFO), and no
// file a loaded scene reads.
void check_output(const std::string& what, const std::string& path, bool image) {
  try {
    if (image)
      check_output_path(path);
    else
      check_writable_path(path);
    check_outputs_distinct({{what, path}}, files_read(), "a loaded scene");
  } catch (const std::runtime_error& e) {
    throw py::value_error(e.what());
  }
}

// A loaded scene: what to load again for each render (a file with its overrides, or a document),
// checked once at load time so that errors surface there.
struct PyScene {
  std::string path;         // a scene file's; "" for a document
  nlohmann::json document;  // a document's (load_dict)
  std::string source;       // its name in messages
  std::vector<std::string> overrides;
  int width = 0, height = 0, spp = 0;
  uint64_t seed = 0;
  // The scene compiled for a seed, for films and render_into: the last one asked for.
  struct Compiled {
    std::optional<uint64_t> seed;
    std::shared_future<std::shared_ptr<const Scene>> scene;  // valid: compiled, or compiling
    uint64_t generation = 0;
  };
  std::shared_ptr<Compiled> compiled = std::make_shared<Compiled>();
};

// The description as a render loads it: the overrides, then the seed if one is given.
SceneDesc reload(const PyScene& scene, std::optional<uint64_t> seed) {
  std::vector<std::string> overrides = scene.overrides;
  if (seed) overrides.push_back("integrator.seed=" + std::to_string(*seed));
  return scene.path.empty() ? load_scene_json(scene.document, scene.source, overrides)
                            : load_scene_file(scene.path, overrides);
}

PyScene describe(const SceneDesc& desc, PyScene s) {
  s.width = desc.settings.width;
  s.height = desc.settings.height;
  s.spp = desc.settings.spp;
  s.seed = desc.settings.seed;
  return s;
}

PyScene load_file(const py::object& path_arg, const std::vector<std::string>& overrides) {
  const std::string path = path_of(path_arg);
  const SceneDesc desc = load_scene_file(path, overrides);
  remember_read({{"the scene file", path}});
  remember_inputs(desc.inputs);
  return describe(desc, PyScene{path, {}, path, overrides});
}

PyScene load_text(const std::string& text, const std::string& source) {
  SceneDesc desc = load_scene_text(text, source);
  remember_inputs(desc.inputs);
  return describe(desc, PyScene{"", desc.document, source, {}});
}

py::array_t<float> to_array(const Image& image) {
  py::array_t<float> a({image.height, image.width, 3});
  std::copy(image.rgb.begin(), image.rgb.end(), a.mutable_data());
  return a;
}

// The job's steps as `nimbus render` takes them, on a worker thread; false if cancelled.
bool prepare(RenderJob& job, const PyScene& scene, const BuildMonitor& monitor) {
  const int spp = job.read_resume();
  if (scene.path.empty())
    job.load_document(scene.document, scene.source, spp);
  else
    job.load(scene.path, spp);
  job.check();
  if (!job.compile(monitor)) return false;
  job.check_compiled();
  return true;
}

// Runs work(stop) on a worker thread while this one, holding the GIL only between waits, polls
// Python's signals (a Ctrl-C raises KeyboardInterrupt here and sets `stop`) and calls `progress`
// with the fraction that work stores. Rethrows what work or progress threw.
void run_interruptible(const std::function<void(const std::atomic<bool>& stop)>& work,
                       const std::atomic<double>& fraction, std::atomic<bool>& stop,
                       const py::object& progress) {
  std::exception_ptr failure, callback_failure;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false, interrupted = false;
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        work(stop);
      } catch (...) {
        failure = std::current_exception();
      }
      std::lock_guard lock(mutex);
      done = true;
      finished.notify_one();
    });
    double reported = -1;
    for (;;) {
      {
        std::unique_lock lock(mutex);
        if (finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
      }
      if (interrupted || callback_failure) continue;
      py::gil_scoped_acquire acquire;
      if (PyErr_CheckSignals() != 0) {
        interrupted = true;  // the KeyboardInterrupt (or a handler's exception) stays set
        stop = true;
        continue;
      }
      const double f = fraction.load(std::memory_order_relaxed);
      if (!progress.is_none() && f != reported) {
        reported = f;
        try {
          progress(f);
        } catch (...) {
          callback_failure = std::current_exception();
          stop = true;
        }
      }
    }
    worker.join();
  }
  if (interrupted) throw py::error_already_set();
  if (callback_failure) std::rethrow_exception(callback_failure);
  if (failure) std::rethrow_exception(failure);
  if (!progress.is_none()) progress(1.0);
}

// The scene's compile warnings (an empty object left out) as UserWarning; the GIL held.
void warn_of(const Scene& scene) {
  for (const std::string& w : scene.warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
}

// A render job as `nimbus render` runs it. Returns the image and the --stats JSON text.
py::tuple render(const PyScene& scene, int spp, std::optional<uint64_t> seed, int threads,
                 const py::object& progress) {
  RenderJobOptions options;
  options.overrides = scene.overrides;
  options.spp = spp;
  options.seed = seed;
  options.threads = threads;
  std::atomic<bool> stop{false};
  std::atomic<double> fraction{0};
  options.cancel = [&stop] { return stop.load(std::memory_order_relaxed); };
  options.progress = [&fraction](double f) { fraction.store(f, std::memory_order_relaxed); };
  RenderJob job(options);
  JobOutcome outcome;
  bool compiled = false;
  run_interruptible(
      [&](const std::atomic<bool>& stopped) {
        compiled = prepare(job, scene, BuildMonitor{nullptr, options.cancel, nullptr});
        if (compiled && !stopped) outcome = job.run();
      },
      fraction, stop, progress);
  remember_read(job.files_read());
  if (compiled) warn_of(job.scene());
  if (!compiled || outcome.stopped) throw std::runtime_error("the render was stopped");
  return py::make_tuple(to_array(to_image(outcome.film)), job.stats(outcome).dump());
}

// The scene compiled for `seed` (its own when none), compiled once for the last seed asked. The
// cache is read and written with the GIL held; the compile runs without it. Threads that ask for
// the seed being compiled wait for that compile (one compile, its warnings once); a compile that
// fails is not kept, so the next call tries again.
std::shared_ptr<const Scene> compiled_scene(const PyScene& scene, std::optional<uint64_t> seed) {
  PyScene::Compiled& cache = *scene.compiled;
  if (cache.scene.valid() && cache.seed == seed) {
    const std::shared_future<std::shared_ptr<const Scene>> pending = cache.scene;
    py::gil_scoped_release release;
    return pending.get();  // or the compile's exception
  }
  std::promise<std::shared_ptr<const Scene>> promise;
  const uint64_t mine = ++cache.generation;
  cache.seed = seed;
  cache.scene = promise.get_future().share();
  std::shared_ptr<const Scene> compiled;
  try {
    const SceneDesc desc = reload(scene, seed);
    std::vector<InputFile> inputs;
    {
      py::gil_scoped_release release;
      compiled = std::make_shared<const Scene>(compile_scene(desc, {}, &inputs));
    }
    remember_inputs(inputs);
  } catch (...) {
    promise.set_exception(std::current_exception());
    if (cache.generation == mine) cache.scene = {};
    throw;
  }
  promise.set_value(compiled);
  warn_of(*compiled);
  return compiled;
}

// A film of the scene's size and light scale (its exponent), for render_into; with a noise
// target, with the half sums its blocks are decided from (render/noise_target.h).
Film film_of(const PyScene& scene) {
  const auto compiled = compiled_scene(scene, std::nullopt);
  AovSet layers;
  if (noise_rule(compiled->settings).on()) layers.add(Aov::Half);
  return Film(compiled->settings.width, compiled->settings.height, compiled->film_exponent, layers);
}

// Samples [s0, s1) of every pixel into the film; a stopped render leaves the film as it was. The
// film is claimed throughout (render/film.h): another thread's render_into or save of it
// meanwhile is a ValueError, where both would have returned and one's samples been lost.
void render_into_film(const PyScene& scene, Film& film, int s0, int s1,
                      std::array<int, 4> pixels, std::optional<uint64_t> seed, int threads,
                      const py::object& progress) {
  const FilmClaim claim(film);
  const auto compiled = compiled_scene(scene, seed);
  if (film.width != compiled->settings.width || film.height != compiled->settings.height)
    throw py::value_error("the film is " + std::to_string(film.width) + "x" +
                          std::to_string(film.height) + ", the scene's image " +
                          std::to_string(compiled->settings.width) + "x" +
                          std::to_string(compiled->settings.height));
  if (film.exponent != compiled->film_exponent)
    throw py::value_error("the film sums another scene's light (its exponent " +
                          std::to_string(film.exponent) + ", the scene's " +
                          std::to_string(compiled->film_exponent) + ")");
  Film into = film;  // the film changes only once every pixel has the range's samples
  std::atomic<bool> stop{false};
  std::atomic<double> fraction{0};
  RenderOptions options;
  options.threads = threads;
  options.range.s0 = s0;
  options.range.s1 = s1;
  options.range.x0 = pixels[0];  // -1 for x1, y1: the image's edge
  options.range.y0 = pixels[1];
  options.range.x1 = pixels[2];
  options.range.y1 = pixels[3];
  options.cancel = [&stop] { return stop.load(std::memory_order_relaxed); };
  options.progress = [&fraction](double f) { fraction.store(f, std::memory_order_relaxed); };
  run_interruptible([&](const std::atomic<bool>&) { render_into(*compiled, into, options); },
                    fraction, stop, progress);
  film = std::move(into);
}

// Per pixel, per channel, of a film: values(pixel) as a float32 (height, width, 3) array.
template <class Values>
py::array_t<float> film_array(const Film& film, Values&& values) {
  py::array_t<float> a({film.height, film.width, 3});
  float* out = a.mutable_data();
  for (int p = 0; p < film.pixels(); ++p) {
    const Rgb v = values(p);
    for (int c = 0; c < 3; ++c) out[3 * p + c] = float(v[c]);
  }
  return a;
}

// A shape of the scene format, compiled to its tape; F's values as written (FUse::Value).
struct PyShape {
  Tape tape;
};

PyShape make_shape(const std::string& shape, const std::string& shapes, const std::string& source) {
  return {compile(
      *load_shape_json(nlohmann::json::parse(shape),
                       shapes.empty() ? nlohmann::json() : nlohmann::json::parse(shapes), source),
      FUse::Value)};
}

using Rows = py::array_t<double, py::array::c_style | py::array::forcecast>;

// The rows of an (n, 3) array; ValueError naming the argument for another shape or a row that is
// not finite.
std::vector<Vec3> rows_of(const Rows& a, const std::string& name) {
  if (a.ndim() != 2 || a.shape(1) != 3) {
    std::string shape;
    for (py::ssize_t i = 0; i < a.ndim(); ++i)
      shape += (i ? ", " : "") + std::to_string(a.shape(i));
    throw py::value_error(name + " must be an array of shape (n, 3), not (" + shape + ")");
  }
  std::vector<Vec3> rows(size_t(a.shape(0)));
  const double* d = a.data();
  for (size_t i = 0; i < rows.size(); ++i) {
    rows[i] = {d[3 * i], d[3 * i + 1], d[3 * i + 2]};
    if (!std::isfinite(rows[i].x) || !std::isfinite(rows[i].y) || !std::isfinite(rows[i].z))
      throw py::value_error(name + "[" + std::to_string(i) + "] is not finite");
  }
  return rows;
}

py::array_t<double> shape_values(const PyShape& s, const Rows& points) {
  const std::vector<Vec3> p = rows_of(points, "points");
  py::array_t<double> out(py::ssize_t(p.size()));
  double* f = out.mutable_data();
  {
    py::gil_scoped_release release;
    tbb::parallel_for(size_t{0}, p.size(), [&](size_t i) { f[i] = evaluate(s.tape, p[i]); });
  }
  return out;
}

py::array_t<double> shape_first_hit(const PyShape& s, const Rows& origins, const Rows& directions,
                                    double t_max) {
  const std::vector<Vec3> o = rows_of(origins, "origins");
  const std::vector<Vec3> d = rows_of(directions, "directions");
  if (o.size() != d.size())
    throw py::value_error("origins and directions must have as many rows (" +
                          std::to_string(o.size()) + " and " + std::to_string(d.size()) + ")");
  for (size_t i = 0; i < d.size(); ++i)
    if (d[i] == Vec3{0, 0, 0})
      throw py::value_error("directions[" + std::to_string(i) + "] is zero");
  if (!(t_max >= 0)) throw py::value_error("t_max must be >= 0");
  py::array_t<double> out(py::ssize_t(o.size()));
  double* t = out.mutable_data();
  {
    py::gil_scoped_release release;
    tbb::parallel_for(size_t{0}, o.size(), [&](size_t i) {
      const std::optional<double> hit = first_hit(s.tape, Ray{o[i], d[i]}, 0, t_max);
      t[i] = hit ? *hit : std::numeric_limits<double>::infinity();
    });
  }
  return out;
}

// The shape's surface as a mesh to the error bound (mesh/polygonize.h): (vertices, faces,
// normals), (n, 3) float64, (m, 3) uint32 and (n, 3) float64. ValueError for a bound <= 0, an
// empty or unbounded shape, or one whose grid would need more memory than is available.
py::tuple shape_mesh(const PyShape& s, double error) {
  TriangleMesh mesh;
  {
    py::gil_scoped_release release;
    try {
      mesh = polygonize(s.tape, {error, available_memory() / kPolygonizeBytesPerCell});
    } catch (const PolygonizeError& e) {
      py::gil_scoped_acquire acquire;
      throw py::value_error(e.what());
    }
  }
  const auto n = py::ssize_t(mesh.positions.size()), m = py::ssize_t(mesh.triangles.size());
  py::array_t<double> vertices({n, py::ssize_t(3)}), normals({n, py::ssize_t(3)});
  py::array_t<std::uint32_t> faces({m, py::ssize_t(3)});
  double* v = vertices.mutable_data();
  double* nn = normals.mutable_data();
  for (py::ssize_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      v[3 * i + k] = mesh.positions[size_t(i)][k];
      nn[3 * i + k] = mesh.normals[size_t(i)][k];
    }
  std::uint32_t* f = faces.mutable_data();
  for (py::ssize_t i = 0; i < m; ++i)
    for (int k = 0; k < 3; ++k) f[3 * i + k] = mesh.triangles[size_t(i)][size_t(k)];
  return py::make_tuple(vertices, faces, normals);
}

// The media's coefficients at points, in rgb, as a path finds them there: each present
// medium's density times its sigma_a and sigma_s, summed (the index-matched media add), inside a
// solid only its own medium. Returns (sigma_a, sigma_s), each (n, 3).
py::tuple media_at(const PyScene& scene, const Rows& points) {
  const std::vector<Vec3> p = rows_of(points, "points");
  const auto compiled = compiled_scene(scene, std::nullopt);
  py::array_t<double> sigma_a({py::ssize_t(p.size()), py::ssize_t(3)});
  py::array_t<double> sigma_s({py::ssize_t(p.size()), py::ssize_t(3)});
  double* a = sigma_a.mutable_data();
  double* b = sigma_s.mutable_data();
  {
    py::gil_scoped_release release;
    const Scene& sc = *compiled;
    tbb::parallel_for(size_t{0}, p.size(), [&](size_t i) {
      Rgb mu_a(0.0), mu_s(0.0);
      const Vec3 x = p[i];
      for_each_medium_at(
          sc, x, solid_containing(sc, x), [&](int m, double density, double F, int object) {
            const Medium& med = sc.media[size_t(m)];
            const Vec3 xt = texture_point(sc, sc.objects[size_t(object)], x);
            mu_a += textured_rgb(med.sigma_a, med.sigma_a_to, med.sigma_a_texture, xt, F) * density;
            mu_s += textured_rgb(med.sigma_s, med.sigma_s_to, med.sigma_s_texture, xt, F) * density;
          });
      for (int c = 0; c < 3; ++c) {
        a[3 * i + c] = mu_a[c];
        b[3 * i + c] = mu_s[c];
      }
    });
  }
  return py::make_tuple(sigma_a, sigma_s);
}

// Runs experiment `name` (docs/reproduction.md) into `out`; returns its files and summary.
py::tuple run_experiment(const std::string& name, const py::object& out, const py::object& scenes,
                         bool quick, uint64_t seed, int threads) {
  for (const Experiment& e : experiments()) {
    if (e.name != name) continue;
    const ExperimentOptions options{path_of(out), path_of(scenes), quick, seed, threads};
    ExperimentReport report;
    {
      py::gil_scoped_release release;
      report = e.run(options);
    }
    std::vector<std::string> files;
    for (const auto& f : report.files) files.push_back(f.string());
    return py::make_tuple(files, report.summary);
  }
  std::string names;
  for (const Experiment& e : experiments()) names += (names.empty() ? "" : ", ") + e.name;
  throw py::value_error("unknown experiment \"" + name + "\" (expected one of: " + names + ")");
}

}  // namespace nimbus_python

PYBIND11_MODULE(_core, m) {
  namespace np = nimbus_python;
  m.doc() = "The compiled part of nimbus; use the package nimbus.";
  m.attr("__version__") = NIMBUS_VERSION;
  m.attr("_build_scenes_dir") = NIMBUS_SCENES_DIR;
  // One line naming the place and the problem, as the command line prints it.
  py::register_exception<nimbus::SceneError>(m, "SceneError", PyExc_ValueError);
  py::register_exception<nimbus::JobError>(m, "JobError", PyExc_RuntimeError);
  py::class_<np::PyScene>(m, "Scene", "A scene loaded by nimbus.load_file or nimbus.load_dict.")
      .def_readonly("width", &np::PyScene::width)
      .def_readonly("height", &np::PyScene::height)
      .def_readonly("spp", &np::PyScene::spp)
      .def_readonly("seed", &np::PyScene::seed)
      .def_readonly("source", &np::PyScene::source)
      .def("media_at", &np::media_at, py::arg("points"),
           "The media's rgb sigma_a and sigma_s at an (n, 3) array of points: two (n, 3) arrays.")
      .def("__repr__", [](const np::PyScene& s) {
        return "<nimbus.Scene " + s.source + ": " + std::to_string(s.width) + "x" +
               std::to_string(s.height) + ", " + std::to_string(s.spp) + " spp>";
      });
  m.def("load_file", &np::load_file, py::arg("path"), py::arg("overrides"));
  m.def("load_text", &np::load_text, py::arg("text"), py::arg("source"));
  m.def("render", &np::render, py::arg("scene"), py::arg("spp"), py::arg("seed"),
        py::arg("threads"), py::arg("progress"));
  py::class_<nimbus::Film>(m, "Film",
                           "Per-pixel sums of a render, which render_into continues exactly.")
      .def(py::init(&np::film_of), py::arg("scene"))
      .def_readonly("width", &nimbus::Film::width)
      .def_readonly("height", &nimbus::Film::height)
      .def_property_readonly(
          "spp",
          [](const nimbus::Film& f) {
            return f.samples.empty() ? 0u : *std::min_element(f.samples.begin(), f.samples.end());
          })
      .def("image", [](const nimbus::Film& f) { return np::to_array(nimbus::to_image(f)); })
      .def(
          "samples",
          [](const nimbus::Film& f) {
            py::array_t<uint32_t> a({f.height, f.width});
            std::copy(f.samples.begin(), f.samples.end(), a.mutable_data());
            return a;
          },
          "Each pixel's sample count, (height, width): with a noise target, its block's.")
      .def("variance",
           [](const nimbus::Film& f) {
             return np::film_array(f, [&](int p) { return f.variance_of_mean(p); });
           })
      .def(
          "save",
          [](nimbus::Film& f, const py::object& path_arg) {
            const std::string path = np::path_of(path_arg);
            np::check_output("Film.save", path, false);
            // Written without the GIL: a render_into ending meanwhile must not replace it.
            const nimbus::FilmClaim claim(f, "saved");
            np::os_errors([&] {
              py::gil_scoped_release release;
              nimbus::save_film(f, path);
            });
          },
          py::arg("path"),
          "Saves the film atomically; the path follows write_image's rules (ValueError), and a "
          "film being rendered into is not saved meanwhile (ValueError).")
      .def_static(
          "load",
          [](const py::object& path_arg) {
            const std::string path = np::path_of(path_arg);
            return np::os_errors([&] {
              py::gil_scoped_release release;
              return nimbus::load_film(path);
            });
          },
          py::arg("path"), "A film saved by Film.save; OSError if the file is not one.")
      .def("__repr__", [](const nimbus::Film& f) {
        return "<nimbus.Film " + std::to_string(f.width) + "x" + std::to_string(f.height) + ">";
      });
  m.def("render_into", &np::render_into_film, py::arg("scene"), py::arg("film"), py::arg("s0"),
        py::arg("s1"), py::arg("pixels"), py::arg("seed"), py::arg("threads"), py::arg("progress"));
  py::class_<np::PyShape>(m, "Shape")
      .def(py::init(&np::make_shape), py::arg("shape"), py::arg("shapes"), py::arg("source"))
      .def("values", &np::shape_values, py::arg("points"))
      .def("first_hit", &np::shape_first_hit, py::arg("origins"), py::arg("directions"),
           py::arg("t_max"))
      .def("mesh", &np::shape_mesh, py::arg("error"))
      .def("bounds", [](const np::PyShape& s) -> py::object {
        const nimbus::Bounds& b = s.tape.bounds;
        if (b.box.empty()) return py::none();
        const auto row = [](const nimbus::Vec3& v) {
          py::array_t<double> a(3);
          for (int i = 0; i < 3; ++i) a.mutable_data()[i] = v[i];
          return a;
        };
        return py::make_tuple(row(b.box.lo), row(b.box.hi));
      });
  m.def("run_experiment", &np::run_experiment, py::arg("name"), py::arg("out"), py::arg("scenes"),
        py::arg("quick"), py::arg("seed"), py::arg("threads"));
  m.def("experiment_names", [] {
    std::vector<std::string> names;
    for (const nimbus::Experiment& e : nimbus::experiments()) names.push_back(e.name);
    return names;
  });
  m.def(
      "write_image",
      [](const py::object& path_arg, py::array_t<float, py::array::c_style> a) {
        const std::string path = np::path_of(path_arg);
        np::check_output("write_image", path, true);
        nimbus::Image image{int(a.shape(1)), int(a.shape(0)), {}};
        image.rgb.assign(a.data(), a.data() + a.size());
        np::os_errors([&] {
          py::gil_scoped_release release;
          nimbus::write_image(path, image);
        });
      },
      py::arg("path"), py::arg("array"));
  m.def(
      "read_exr",
      [](const py::object& path_arg, const std::string& layer) {
        const std::string path = np::path_of(path_arg);
        const nimbus::Image image = np::os_errors([&] {
          py::gil_scoped_release release;
          return nimbus::read_exr(path);
        });
        if (layer.empty()) return np::to_array(image);
        std::vector<std::string> names;
        for (const nimbus::ImageLayer& l : image.layers) {
          if (l.name != layer) {
            names.push_back(l.name);
            continue;
          }
          const auto k = py::ssize_t(l.channels.size());
          py::array_t<float> a({py::ssize_t(image.height), py::ssize_t(image.width), k});
          std::copy(l.values.begin(), l.values.end(), a.mutable_data());
          return a;
        }
        throw py::value_error(
            fmt::format("{}: no layer \"{}\" (the file's layers: {})", path, layer,
                        names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "))));
      },
      py::arg("path"), py::arg("layer"));
}
