// rastray._core: the Python module's native part (pybind11). python/rastray/
// __init__.py turns keyword options into the command line's words and wraps
// these functions; everything here goes through the libraries the rastray
// program uses (app/engine, app/crossval, compare/), so a Python render is
// the command line's render bit for bit.
//
// Invariants:
// - Arrays handed to numpy are views of the C++ buffers (no copy); each
//   holds, through a capsule, a shared_ptr to the object owning the buffer,
//   so a view outlives the Frame it came from. They are read-only: a frame
//   is compared and saved from the same buffers.
// - The GIL is released while loading, rendering and comparing. A call from
//   the main thread runs the work on a helper thread and polls
//   PyErr_CheckSignals every 50 ms; on Ctrl-C it cancels the render's
//   CancelToken (common/interrupt.h: the renderers stop within about one
//   tile per thread), waits for the helper, then raises KeyboardInterrupt.
//   Calls from other threads run in place (Python delivers signals to the
//   main thread only).
// - `threads` runs the render in a task arena of that many threads (not the
//   process-wide tbb::global_control the command line uses), so concurrent
//   renders from several Python threads keep their own limits.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <tbb/task_arena.h>

#include "app/crossval/crossval.h"
#include "app/crossval/crossval_record.h"
#include "app/crossval/explain.h"
#include "app/engine/render_options.h"
#include "app/engine/render_setup.h"
#include "app/engine/scene_info.h"
#include "common/error.h"
#include "common/gltf/loader.h"
#include "common/image.h"
#include "common/interrupt.h"
#include "common/one_line.h"
#include "compare/color_metrics.h"
#include "compare/compare_files.h"
#include "compare/maps.h"

namespace py = pybind11;

namespace rastray {
namespace {

static_assert(sizeof(glm::vec4) == 4 * sizeof(float), "colour arrays view glm::vec4 as 4 packed floats");
static_assert(sizeof(uint32_t) == sizeof(int32_t), "IDs are viewed as int32 (kNoId reads as -1)");

// ---- errors -----------------------------------------------------------------

PyObject* inputErrorType = nullptr;  // rastray.InputError, a ValueError

// A str or os.PathLike as a path.
std::string fspath(const py::object& path) {
  return py::module_::import("os").attr("fspath")(path).cast<std::string>();
}

// ---- Ctrl-C -----------------------------------------------------------------

unsigned long mainThreadId = 0;

// Runs work() without the GIL (see the invariants above); `token` is the
// render's, cancelled on Ctrl-C. Exceptions from work() propagate.
template <class Work>
auto runInterruptibly(CancelToken& token, Work work) -> decltype(work()) {
  using Result = decltype(work());
  if (PyThread_get_thread_ident() != mainThreadId) {
    py::gil_scoped_release release;
    return work();
  }
  std::optional<Result> result;
  std::exception_ptr error;
  bool done = false;
  std::mutex mutex;
  std::condition_variable finished;
  PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;  // the KeyboardInterrupt, if any
  {
    py::gil_scoped_release release;
    std::thread helper([&] {
      try {
        result.emplace(work());
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(mutex);
      done = true;
      finished.notify_one();
    });
    std::unique_lock<std::mutex> lock(mutex);
    while (!finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) {
      if (type) continue;  // cancelled already: wait for the helper
      lock.unlock();
      {
        py::gil_scoped_acquire acquire;
        if (PyErr_CheckSignals() != 0) {
          PyErr_Fetch(&type, &value, &traceback);
          token.cancel();
        }
      }
      lock.lock();
    }
    lock.unlock();
    helper.join();
  }
  if (type) {
    // The signal handler's exception (KeyboardInterrupt), whatever the
    // render did after the cancel (stopped, or finished first).
    PyErr_Restore(type, value, traceback);
    throw py::error_already_set();
  }
  if (error) std::rethrow_exception(error);
  return std::move(*result);
}

// Runs f in a task arena of `threads` threads (0: all cores).
template <class F>
auto inArena(int threads, F f) -> decltype(f()) {
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  return arena.execute(f);
}

// ---- arrays -------------------------------------------------------------------

// A read-only numpy view of `data` kept alive by `owner`.
template <class Owner>
py::array view(const std::shared_ptr<Owner>& owner, const py::dtype& dtype, std::vector<py::ssize_t> shape,
               std::vector<py::ssize_t> strides, const void* data) {
  auto* keep = new std::shared_ptr<Owner>(owner);
  py::capsule capsule(keep, [](void* p) { delete static_cast<std::shared_ptr<Owner>*>(p); });
  py::array a(dtype, std::move(shape), std::move(strides), data, capsule);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

template <class Owner>
py::array imagePlane(const std::shared_ptr<Owner>& owner, int width, int height, const py::dtype& dtype,
                     const void* data) {
  const py::ssize_t item = dtype.itemsize();
  return view(owner, dtype, {height, width}, {item * width, item}, data);
}

py::object fromJson(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }
py::object fromJson(const nlohmann::ordered_json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// The structured dtype of one DeepSample (common/image.h), laid over the
// C++ struct: color (4 float32, premultiplied), depth, instance and triangle
// (int32, -1: none), sample (index in the SPEC §3 pattern), cut_off.
py::dtype deepSampleDtype() {
  py::list names, formats, offsets;
  auto field = [&](const char* name, const char* format, size_t offset) {
    names.append(name);
    formats.append(format);
    offsets.append(offset);
  };
  field("color", "(4,)<f4", offsetof(DeepSample, color));
  field("depth", "<f4", offsetof(DeepSample, depth));
  field("instance", "<i4", offsetof(DeepSample, instance));
  field("triangle", "<i4", offsetof(DeepSample, triangle));
  field("sample", "<u4", offsetof(DeepSample, sample));
  field("cut_off", "?", offsetof(DeepSample, cutOff));
  py::dict d;
  d["names"] = names;
  d["formats"] = formats;
  d["offsets"] = offsets;
  d["itemsize"] = sizeof(DeepSample);
  return py::dtype::from_args(d);
}

// ---- scenes -------------------------------------------------------------------

struct PyScene {
  std::shared_ptr<const Scene> scene;  // as loaded: each render prepares a copy (lights, origin)
};

// The scene prepared for `settings` (selectLights, render origin), as
// loadSceneForRender gives the command line. Another pose (time=,
// animation=) than the one loaded loads the file again at that pose.
std::shared_ptr<const Scene> prepared(const PyScene& s, const RenderSettings& settings) {
  auto scene = settings.pose == s.scene->pose
                   ? std::make_shared<Scene>(*s.scene)
                   : std::make_shared<Scene>(loadScene(s.scene->path, settings.memory, settings.pose));
  prepareSceneForRender(*scene, settings);
  return scene;
}

// ---- frames -------------------------------------------------------------------

struct FrameData {
  FlatImage image;
  DeepImage deep;
  bool hasDeep = false;
  // From a render (absent for a frame read from a file):
  std::shared_ptr<const Scene> scene;  // the prepared scene, for compare's classification
  std::optional<RenderSettings> settings;
  Camera camera;
  CounterSet counters;
  std::vector<std::pair<std::string, double>> timings;
  std::vector<std::string> passesRun, passesLeftOut;
  double seconds = 0.0;
  std::string path;  // read from this file
};

struct PyFrame {
  std::shared_ptr<FrameData> d;
};

std::shared_ptr<FrameData> frameFromRun(RenderRun run, std::shared_ptr<const Scene> scene,
                                        const RenderSettings& settings) {
  auto d = std::make_shared<FrameData>();
  d->image = std::move(run.output.image);
  d->hasDeep = run.output.hasSamples;
  d->deep = std::move(run.output.samples);
  d->scene = std::move(scene);
  d->settings = settings;
  d->camera = run.camera;
  d->counters = std::move(run.output.counters);
  d->timings = std::move(run.output.timings);
  d->passesRun = std::move(run.output.passesRun);
  d->passesLeftOut = std::move(run.output.passesLeftOut);
  d->seconds = run.seconds;
  return d;
}

struct PyDeep {
  std::shared_ptr<FrameData> d;
  py::array samples() const {
    // Never destroyed: a static py::object would be released after the
    // interpreter has finalized.
    static const py::dtype* dtype = new py::dtype(deepSampleDtype());
    return view(d, *dtype, {py::ssize_t(d->deep.samples.size())}, {py::ssize_t(sizeof(DeepSample))},
                d->deep.samples.data());
  }
  py::array offsets() const {
    return view(d, py::dtype::of<uint64_t>(), {py::ssize_t(d->deep.offsets.size())},
                {py::ssize_t(sizeof(uint64_t))}, d->deep.offsets.data());
  }
  // Every sample and layer of pixel (x, y), front to back within each sample.
  py::object pixel(int x, int y) const {
    if (x < 0 || y < 0 || x >= d->deep.width || y >= d->deep.height)
      throw py::index_error("pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") lies outside the " +
                            std::to_string(d->deep.width) + "x" + std::to_string(d->deep.height) + " image");
    const size_t i = size_t(y) * size_t(d->deep.width) + size_t(x);
    return samples()[py::slice(py::ssize_t(d->deep.offsets[i]), py::ssize_t(d->deep.offsets[i + 1]), 1)];
  }
};

// ---- rendering ----------------------------------------------------------------

PyFrame render(const PyScene& s, const std::vector<std::string>& args, bool deep) {
  RenderSettings settings = renderSettingsFrom(args, /*allRenderers=*/false);
  settings.keepSamples = deep;
  CancelToken token;
  settings.raster.cancel = &token;
  settings.ray.cancel = &token;
  auto d = runInterruptibly(token, [&] {
    return inArena(settings.threads, [&] {
      std::shared_ptr<const Scene> scene = prepared(s, settings);
      RenderRun run = renderScene(*scene, settings);
      return frameFromRun(std::move(run), std::move(scene), settings);
    });
  });
  d->settings->raster.cancel = d->settings->ray.cancel = nullptr;  // the token dies here
  return {d};
}

struct CrossvalData {
  CrossvalResult result;
  nlohmann::json summary;
  std::shared_ptr<const Scene> scene;
  RenderSettings settings;
};

struct PyCrossval {
  std::shared_ptr<CrossvalData> d;
  std::optional<PyFrame> raster, raytrace, hybrid;
};

PyFrame frameOf(RenderRun& run, const std::shared_ptr<const Scene>& scene, const RenderSettings& settings,
                RendererKind kind) {
  RenderSettings s = settings;
  s.renderer = kind;
  s.allRenderers = false;
  return {frameFromRun(std::move(run), scene, s)};
}

PyCrossval crossval(const PyScene& s, const std::vector<std::string>& args) {
  auto d = std::make_shared<CrossvalData>();
  d->settings = renderSettingsFrom(args, /*allRenderers=*/true);
  CancelToken token;
  d->settings.raster.cancel = d->settings.ray.cancel = &token;
  runInterruptibly(token, [&] {
    return inArena(d->settings.threads, [&] {
      d->scene = prepared(s, d->settings);
      d->result = crossvalidate(*d->scene, d->settings, nullptr);
      d->summary = summaryJson(summarize(d->result, d->settings.spp));
      return 0;
    });
  });
  d->settings.raster.cancel = d->settings.ray.cancel = nullptr;
  PyCrossval c{d, {}, {}, {}};
  // The frames take the renders' images and samples; the maps stay in d.
  c.raster = frameOf(d->result.raster, d->scene, d->settings, RendererKind::Raster);
  c.raytrace = frameOf(d->result.raytrace, d->scene, d->settings, RendererKind::Raytrace);
  c.hybrid = frameOf(d->result.hybrid, d->scene, d->settings, RendererKind::Hybrid);
  return c;
}

py::object explain(const PyScene& s, int x, int y, const std::vector<std::string>& args) {
  RenderSettings settings = renderSettingsFrom(args, /*allRenderers=*/true);
  if (x < 0 || y < 0 || x >= settings.camera.width() || y >= settings.camera.height())
    throw InputError("command line", "X Y",
                     "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") lies outside the image");
  CancelToken token;
  settings.raster.cancel = settings.ray.cancel = &token;
  const PixelExplanation e = runInterruptibly(token, [&] {
    return inArena(settings.threads, [&] {
      std::shared_ptr<const Scene> scene = prepared(s, settings);
      return explainPixel(*scene, settings, x, y);
    });
  });
  return fromJson(explanationJson(e));
}

// ---- comparing ----------------------------------------------------------------

struct CompareData {
  CompareResult result;
};

struct PyComparison {
  std::shared_ptr<CompareData> d;
};

FlatImage flatOf(const FrameData& f, int spp) { return f.hasDeep ? flattenDeepColor(f.deep, spp) : f.image; }

// Two frames (at least one rendered here): classified against the rendered
// frame's scene and camera, with its rasterizer's depth format, as crossval.
PyComparison compareFrames(const FrameData& a, const FrameData& b, const std::string& nameA,
                           const std::string& nameB, bool deep) {
  const FrameData& rendered = a.settings ? a : b;
  const RenderSettings& settings = *rendered.settings;
  const int spp = settings.spp;
  const FrameData& other = a.settings ? b : a;
  if (other.settings && other.settings->spp != spp)
    throw InputError("command line", "compare",
                     "the frames were rendered at " + std::to_string(a.settings->spp) + " and " +
                         std::to_string(b.settings->spp) + " spp: compare frames of one pattern");
  if (other.scene && other.scene->path != rendered.scene->path)
    throw InputError("command line", "compare",
                     "the frames show different scenes (" + a.scene->path + ", " + b.scene->path + ")");
  // The depth buffer the rasterizing side wrote (float-reversed between ray casts).
  DepthFormat depthFormat = DepthFormat::FloatReversed;
  for (const FrameData* f : {&a, &b})
    if (f->settings && f->settings->renderer != RendererKind::Raytrace)
      depthFormat = f->settings->raster.depthFormat;
  const ClassifierSettings classifier = classifierSettings(*rendered.scene, rendered.camera, depthFormat);
  auto d = std::make_shared<CompareData>();
  CompareResult& r = d->result;
  r.pathA = nameA;
  r.pathB = nameB;
  r.scenePath = rendered.scene->path;
  r.camera = rendered.camera.describe();
  const FrameNames names{nameA, nameB};
  if (deep) {
    r.visibility = compareVisibility(a.deep, b.deep, spp, classifier, names);
  } else {
    r.visibility = compareVisibility(a.image, b.image, spp, classifier, names);
  }
  r.colorA = flatOf(a, spp);
  r.colorB = flatOf(b, spp);
  if (!r.colorA.hasColor || !r.colorB.hasColor)
    r.colorSkipped = std::string(r.colorA.hasColor ? nameB : nameA) + " has no R, G and B channels";
  else
    r.color = compareColors(r.colorA, r.colorB);
  return {d};
}

std::shared_ptr<FrameData> readFrame(const std::string& path) {
  auto d = std::make_shared<FrameData>();
  d->path = path;
  if (isDeepExr(path)) {
    // A deep file's flat view needs its spp (flattenDeepColor): the frame
    // holds the samples only, and its flat planes are None.
    d->deep = readDeepExr(path);
    d->hasDeep = true;
    d->image.width = d->deep.width;
    d->image.height = d->deep.height;
    d->image.hasColor = d->deep.hasColor;
  } else {
    d->image = readExr(path);
  }
  return d;
}

py::object compare(py::object a, py::object b, const std::string& scenePath, int spp) {
  const bool frameA = py::isinstance<PyFrame>(a), frameB = py::isinstance<PyFrame>(b);
  if (!frameA && !frameB) {
    CompareInputs in;
    in.pathA = py::str(a);
    in.pathB = py::str(b);
    in.scenePath = scenePath;
    in.spp = spp;
    CancelToken unused;  // comparing files polls no token: Ctrl-C waits for the end
    auto d = std::make_shared<CompareData>();
    d->result = runInterruptibly(unused, [&] { return compareFiles(in); });
    return py::cast(PyComparison{d});
  }
  if (!scenePath.empty() || spp > 0)
    throw InputError("command line", frameA ? "scene" : "spp",
                     "a rendered frame brings its scene and spp: give scene and spp only with two files");
  std::shared_ptr<FrameData> fa = frameA ? a.cast<PyFrame>().d : readFrame(py::str(a));
  std::shared_ptr<FrameData> fb = frameB ? b.cast<PyFrame>().d : readFrame(py::str(b));
  if (!fa->settings && !fb->settings)
    throw InputError("command line", "compare", "two frames read from files: pass their paths instead");
  if (fa->hasDeep != fb->hasDeep)
    throw InputError(frameB ? "B" : std::string(py::str(b)), "",
                     std::string(fb->hasDeep ? "deep" : "flat") + " frame, but A is " +
                         (fa->hasDeep ? "deep" : "flat") + ": compare frames of the same kind");
  const std::string nameA = frameA ? "A" : std::string(py::str(a)),
                    nameB = frameB ? "B" : std::string(py::str(b));
  CancelToken unused;
  return py::cast(
      runInterruptibly(unused, [&] { return compareFrames(*fa, *fb, nameA, nameB, fa->hasDeep); }));
}

// The per-pixel maps of a visibility report, viewed from `owner`.
template <class Owner>
py::array mismatchMap(const std::shared_ptr<Owner>& owner, const VisibilityReport& v) {
  static_assert(sizeof(PixelVisibility) == 1, "the map is uint8");
  return imagePlane(owner, v.width, v.height, py::dtype::of<uint8_t>(), v.pixels.data());
}
template <class Owner>
py::array depthErrorMap(const std::shared_ptr<Owner>& owner, const VisibilityReport& v) {
  return imagePlane(owner, v.width, v.height, py::dtype::of<float>(), v.pixelDepthError.data());
}

// ---- options ------------------------------------------------------------------

py::list optionTable() {
  py::list rows;
  for (const RenderOptionSpec& spec : renderOptionTable()) {
    py::dict row;
    row["name"] = spec.name;
    row["arity"] = spec.arity;
    row["default"] = defaultText(spec);
    row["applies_to"] = describeWhereApplies(spec);
    row["help"] = spec.help;
    rows.append(row);
  }
  return rows;
}

}  // namespace
}  // namespace rastray

PYBIND11_MODULE(_core, m) {
  using namespace rastray;
  m.doc() = "rastray's native part; use the rastray package (python/rastray/__init__.py)";
  mainThreadId = py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
  // An internal check failed (common/error.h): say so before the abort.
  setCheckFailureHandler([](const std::string& message) {
    std::fprintf(stderr, "rastray: %s\n", message.c_str());
    std::fflush(stderr);
  });

  // Never destroyed, as the dtype above.
  inputErrorType = (new py::exception<InputError>(m, "InputError", PyExc_ValueError))->ptr();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(inputErrorType, oneLine(e.what()).c_str());
    } catch (const Interrupted&) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
    } catch (const Cancelled&) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
    }
  });

  py::class_<PyScene>(m, "Scene")
      .def_property_readonly("path", [](const PyScene& s) { return s.scene->path; })
      .def("info_json",
           [](const PyScene& s, const std::vector<std::string>& args) {
             // `info` takes the camera rows only (--camera to --size) and
             // the pose (--time, --animation), as the command line's.
             static const std::set<std::string> kCamera = {"--camera", "--eye",      "--target", "--up",
                                                           "--yfov",   "--znear",    "--zfar",   "--size",
                                                           "--time",   "--animation"};
             for (const std::string& word : args)
               if (word.rfind("--", 0) == 0 && !kCamera.count(word))
                 throw InputError("command line", word,
                                  "info takes the camera options only (camera to size)");
             const RenderSettings settings = renderSettingsFrom(args, /*allRenderers=*/false);
             if (settings.pose != s.scene->pose)  // another frame: loaded at its pose, as `info --time`
               return fromJson(sceneInfoJson(
                   loadScene(s.scene->path, MemoryBudget::machineDefault(), settings.pose), settings.camera));
             return fromJson(sceneInfoJson(*s.scene, settings.camera));
           })
      .def("__repr__", [](const PyScene& s) {
        return "<rastray.Scene '" + s.scene->path + "': " + std::to_string(s.scene->triangles.size()) +
               " triangles>";
      });

  m.def("load", [](const std::string& path) {
    CancelToken unused;  // loading polls no token: Ctrl-C waits for the end of the load
    auto scene = runInterruptibly(unused, [&] { return std::make_shared<const Scene>(loadScene(path)); });
    return PyScene{scene};
  });

  py::class_<PyDeep>(m, "DeepLayers")
      .def_property_readonly("samples", &PyDeep::samples)
      .def_property_readonly("offsets", &PyDeep::offsets)
      .def_property_readonly("width", [](const PyDeep& d) { return d.d->deep.width; })
      .def_property_readonly("height", [](const PyDeep& d) { return d.d->deep.height; })
      .def("pixel", &PyDeep::pixel, py::arg("x"), py::arg("y"));

  py::class_<PyFrame>(m, "Frame")
      .def_property_readonly("width", [](const PyFrame& f) { return f.d->image.width; })
      .def_property_readonly("height", [](const PyFrame& f) { return f.d->image.height; })
      .def_property_readonly("color",
                             [](const PyFrame& f) -> py::object {
                               const FlatImage& im = f.d->image;
                               if (im.color.empty()) return py::none();  // a deep file: see deep
                               const py::ssize_t fs = sizeof(float);
                               return view(f.d, py::dtype::of<float>(), {im.height, im.width, 4},
                                           {fs * 4 * im.width, fs * 4, fs}, im.color.data());
                             })
      .def_property_readonly("depth",
                             [](const PyFrame& f) -> py::object {
                               const FlatImage& im = f.d->image;
                               if (im.depth.empty()) return py::none();
                               return imagePlane(f.d, im.width, im.height, py::dtype::of<float>(),
                                                 im.depth.data());
                             })
      .def_property_readonly("instance",
                             [](const PyFrame& f) -> py::object {
                               const FlatImage& im = f.d->image;
                               if (im.instance.empty()) return py::none();
                               return imagePlane(f.d, im.width, im.height, py::dtype::of<int32_t>(),
                                                 im.instance.data());
                             })
      .def_property_readonly("triangle",
                             [](const PyFrame& f) -> py::object {
                               const FlatImage& im = f.d->image;
                               if (im.triangle.empty()) return py::none();
                               return imagePlane(f.d, im.width, im.height, py::dtype::of<int32_t>(),
                                                 im.triangle.data());
                             })
      .def_property_readonly("has_color", [](const PyFrame& f) { return f.d->image.hasColor; })
      .def_property_readonly("deep",
                             [](const PyFrame& f) -> py::object {
                               if (!f.d->hasDeep) return py::none();
                               return py::cast(PyDeep{f.d});
                             })
      .def_property_readonly("counters",
                             [](const PyFrame& f) {
                               py::dict d;
                               for (const auto& [name, value] : f.d->counters.values)
                                 d[py::str(name)] = value;
                               return d;
                             })
      .def_property_readonly("timings",
                             [](const PyFrame& f) {
                               py::dict d;
                               for (const auto& [name, value] : f.d->timings) d[py::str(name)] = value;
                               return d;
                             })
      .def_property_readonly("passes_run", [](const PyFrame& f) { return f.d->passesRun; })
      .def_property_readonly("left_out", [](const PyFrame& f) { return f.d->passesLeftOut; })
      .def_property_readonly("seconds", [](const PyFrame& f) { return f.d->seconds; })
      .def_property_readonly("renderer",
                             [](const PyFrame& f) -> py::object {
                               if (!f.d->settings) return py::none();
                               return py::str(toString(f.d->settings->renderer));
                             })
      .def_property_readonly("spp",
                             [](const PyFrame& f) -> py::object {
                               if (!f.d->settings) return py::none();
                               return py::int_(f.d->settings->spp);
                             })
      .def_property_readonly("camera",
                             [](const PyFrame& f) -> py::object {
                               if (!f.d->settings) return py::none();
                               return py::str(f.d->camera.describe());
                             })
      .def_property_readonly("args",
                             [](const PyFrame& f) -> py::object {
                               if (!f.d->settings) return py::none();
                               return py::cast(toArgs(*f.d->settings));
                             })
      .def_property_readonly("path",
                             [](const PyFrame& f) -> py::object {
                               if (f.d->path.empty()) return py::none();
                               return py::str(f.d->path);
                             })
      .def(
          "save",
          [](const PyFrame& f, const py::object& file, bool floatColor) {
            const std::string path = fspath(file);
            if (f.d->image.color.empty())
              throw InputError(path, "", "a frame read from a deep file has no flat planes: use save_deep");
            CancelToken unused;
            runInterruptibly(unused, [&] {
              writeImage(path, f.d->image, floatColor ? ColorPrecision::Float : ColorPrecision::Half);
              return 0;
            });
          },
          py::arg("path"), py::arg("float_color") = false)
      .def(
          "save_deep",
          [](const PyFrame& f, const py::object& file) {
            const std::string path = fspath(file);
            if (!f.d->hasDeep)
              throw InputError(path, "", "the frame has no samples: render it with deep=True");
            CancelToken unused;
            runInterruptibly(unused, [&] {
              writeDeepExr(path, f.d->deep);
              return 0;
            });
          },
          py::arg("path"));

  m.def("render", &render);
  m.def("read_exr", [](const std::string& path) {
    CancelToken unused;
    return PyFrame{runInterruptibly(unused, [&] { return readFrame(path); })};
  });

  py::class_<PyCrossval>(m, "Crossval")
      .def_property_readonly("summary", [](const PyCrossval& c) { return fromJson(c.d->summary); })
      .def_property_readonly("mismatch_map",
                             [](const PyCrossval& c) { return mismatchMap(c.d, c.d->result.rasterVsRay); })
      .def_property_readonly("hybrid_mismatch_map",
                             [](const PyCrossval& c) { return mismatchMap(c.d, c.d->result.hybridVsRay); })
      .def_property_readonly("depth_error",
                             [](const PyCrossval& c) { return depthErrorMap(c.d, c.d->result.rasterVsRay); })
      .def_property_readonly("raster", [](const PyCrossval& c) { return *c.raster; })
      .def_property_readonly("raytrace", [](const PyCrossval& c) { return *c.raytrace; })
      .def_property_readonly("hybrid", [](const PyCrossval& c) { return *c.hybrid; });
  m.def("crossval", &crossval);
  m.def("explain", &explain);

  py::class_<PyComparison>(m, "Comparison")
      .def_property_readonly("summary",
                             [](const PyComparison& c) { return fromJson(toJson(c.d->result, {}, {})); })
      .def_property_readonly("mismatch_map",
                             [](const PyComparison& c) { return mismatchMap(c.d, c.d->result.visibility); })
      .def_property_readonly(
          "depth_error", [](const PyComparison& c) { return depthErrorMap(c.d, c.d->result.visibility); });
  m.def("compare", &compare);

  m.def("option_table", &optionTable);
  m.def("split_option_value", &splitOptionValue);
  // The mismatch map's values (PixelVisibility) in order: (key, label, sRGB).
  m.def("pixel_classes", [] {
    py::list classes;
    for (const LegendEntry& e : mismatchLegend())
      classes.append(
          py::make_tuple(int(e.value), e.key, e.label, py::make_tuple(e.srgb.x, e.srgb.y, e.srgb.z)));
    return classes;
  });
}
