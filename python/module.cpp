// nimbus._core, the compiled part of the Python package nimbus (python/nimbus/__init__.py, which
// checks the arguments and documents the API): scenes loaded as the command line loads them,
// rendered by the same RenderJob into the pixels `nimbus render` writes, with the GIL released
// while rendering and SIGINT turned into KeyboardInterrupt.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "nimbus/io/exr.h"
#include "nimbus/io/film_image.h"
#include "nimbus/job/render_job.h"
#include "nimbus/scene/load.h"

namespace py = pybind11;

namespace nimbus_python {

using namespace nimbus;

// A loaded scene: what to load again for each render (a file with its overrides, or a document),
// checked once at load time so that errors surface there.
struct PyScene {
  std::string path;         // a scene file's; "" for a document
  nlohmann::json document;  // a document's (load_dict)
  std::string source;       // its name in messages
  std::vector<std::string> overrides;
  int width = 0, height = 0, spp = 0;
  uint64_t seed = 0;
};

PyScene describe(const SceneDesc& desc, PyScene s) {
  s.width = desc.settings.width;
  s.height = desc.settings.height;
  s.spp = desc.settings.spp;
  s.seed = desc.settings.seed;
  return s;
}

PyScene load_file(const std::string& path, const std::vector<std::string>& overrides) {
  return describe(load_scene_file(path, overrides), PyScene{path, {}, path, overrides});
}

PyScene load_text(const std::string& text, const std::string& source) {
  SceneDesc desc = load_scene_text(text, source);
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

// Renders on a worker thread while this one, holding the GIL only between waits, polls Python's
// signals (a Ctrl-C raises KeyboardInterrupt here and cancels the job) and calls `progress` with
// the fraction done. Returns the image and the --stats JSON text.
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
  std::exception_ptr failure;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  bool interrupted = false;
  std::exception_ptr callback_failure;
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        const BuildMonitor monitor{nullptr, options.cancel, nullptr};
        compiled = prepare(job, scene, monitor);
        if (compiled && !stop) outcome = job.run();
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
  if (!compiled || outcome.stopped) throw std::runtime_error("the render was stopped");
  if (!progress.is_none()) progress(1.0);
  return py::make_tuple(to_array(to_image(outcome.film)), job.stats(outcome).dump());
}

}  // namespace nimbus_python

PYBIND11_MODULE(_core, m) {
  namespace np = nimbus_python;
  m.doc() = "The compiled part of nimbus; use the package nimbus.";
  m.attr("__version__") = NIMBUS_VERSION;
  // One line naming the place and the problem, as the command line prints it.
  py::register_exception<nimbus::SceneError>(m, "SceneError", PyExc_ValueError);
  py::register_exception<nimbus::JobError>(m, "JobError", PyExc_RuntimeError);
  py::class_<np::PyScene>(m, "Scene", "A scene loaded by nimbus.load_file or nimbus.load_dict.")
      .def_readonly("width", &np::PyScene::width)
      .def_readonly("height", &np::PyScene::height)
      .def_readonly("spp", &np::PyScene::spp)
      .def_readonly("seed", &np::PyScene::seed)
      .def_readonly("source", &np::PyScene::source)
      .def("__repr__", [](const np::PyScene& s) {
        return "<nimbus.Scene " + s.source + ": " + std::to_string(s.width) + "x" +
               std::to_string(s.height) + ", " + std::to_string(s.spp) + " spp>";
      });
  m.def("load_file", &np::load_file, py::arg("path"), py::arg("overrides"));
  m.def("load_text", &np::load_text, py::arg("text"), py::arg("source"));
  m.def("render", &np::render, py::arg("scene"), py::arg("spp"), py::arg("seed"),
        py::arg("threads"), py::arg("progress"));
  m.def(
      "read_exr",
      [](const std::string& path) {
        nimbus::Image image;
        {
          py::gil_scoped_release release;
          image = nimbus::read_exr(path);
        }
        return np::to_array(image);
      },
      py::arg("path"));
}
