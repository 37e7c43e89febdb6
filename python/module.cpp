// _candela: the compiled half of the `candela` Python package. candela/__init__.py holds the other
// half (keyword checking, the Image type, the exception types, progress bars) and is what users
// import; this file only crosses the language boundary. Every render goes through the library's
// RenderRequest (integrators/render_request.h), as the command line's do, so the same settings give the
// same bytes and the same refusals.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <variant>

#include "candela/base/error.h"
#include "candela/denoise/denoise_file.h"
#include "candela/denoise/denoised_render.h"
#include "candela/film/aov_film.h"
#include "candela/film/film.h"
#include "candela/film/image_io.h"
#include "candela/io/json_writer.h"
#include "candela/io/scene_reader.h"
#include "candela/description/render_options.h"
#include "candela/integrators/render_request.h"
#include "candela/render/first_hit_aovs.h"
#include "candela/scene/parameters.h"
#include "candela/scene/resource_limits.h"
#include "candela/scene/scene.h"
#include "candela/textures/texture.h"

namespace py = pybind11;
using namespace candela;

namespace {

// A loaded scene: the description every render builds from. Its files are read once, when it is
// loaded: the meshes are in the description, and the images (textures, environment maps) are held
// here, so that each render's build finds them in read_image_shared's cache.
struct PyScene {
  SceneDesc desc;
  std::string name;  // the file as given, or "<dict>"
  std::vector<std::shared_ptr<const Image>> images;
  std::mutex busy;   // one render or edit at a time
};

// The package's exception types (candela.SceneError, candela.UsageError), handed over by
// __init__.py. Held without reference counting: they live as long as the interpreter.
py::handle g_scene_error, g_usage_error;

// render()'s keywords, from the option table (description/render_options.h): the kind of each,
// for the package's type checks: int, uint, float, str or bool.
py::dict request_kinds() {
  py::dict kinds;
  for (const RenderOption& option : render_options()) {
    if (!option.python) continue;
    const char* kind = std::visit(
        [](auto member) -> const char* {
          using T = std::remove_reference_t<decltype(std::declval<RenderRequest&>().*member)>;
          if constexpr (std::is_same_v<T, std::optional<int>>) return "int";
          else if constexpr (std::is_same_v<T, std::optional<uint64_t>>) return "uint";
          else if constexpr (std::is_same_v<T, std::string>) return "str";
          else if constexpr (std::is_same_v<T, bool>) return "bool";
          else return "float";
        },
        option.field);
    kinds[py::str(option.name)] = kind;
  }
  return kinds;
}

// The request from keywords the package has already checked for kind.
RenderRequest request_from(const py::dict& keywords) {
  RenderRequest request;
  for (auto [key, value] : keywords) {
    auto name = key.cast<std::string>();
    const RenderOption* option = find_render_option(name);
    if (!option || !option->python) throw py::type_error("render() got an unexpected keyword argument '" + name + "'");
    std::visit(
        [&](auto member) {
          using T = std::remove_reference_t<decltype(request.*member)>;
          if constexpr (std::is_same_v<T, std::string> || std::is_same_v<T, bool>)
            request.*member = value.cast<T>();
          else
            request.*member = value.cast<typename T::value_type>();
        },
        option->field);
  }
  request.quiet = true;  // the package draws its own progress; notes would go past Python's stderr
  return request;
}

// A float32 (height, width, channels) array, or (height, width) for one channel, that owns
// `values` (row-major, no copy).
py::array_t<float> to_array(std::vector<float>&& values, int width, int height, int channels) {
  auto* pixels = new std::vector<float>(std::move(values));
  py::capsule owner(pixels, [](void* p) { delete static_cast<std::vector<float>*>(p); });
  const auto w = py::ssize_t(width), h = py::ssize_t(height), c = py::ssize_t(channels);
  const auto f = py::ssize_t(sizeof(float));
  if (channels == 1) return py::array_t<float>({h, w}, {w * f, f}, pixels->data(), owner);
  return py::array_t<float>({h, w, c}, {w * c * f, c * f, f}, pixels->data(), owner);
}

// A float32 (height, width, 3) array that owns `image`'s pixels (no copy).
py::array_t<float> to_array(Image&& image) {
  return to_array(std::move(image.rgb), image.width, image.height, 3);
}

// The denoiser's input as the keyword arguments of the package's denoise() (which render(denoise=True)
// keeps beside its image, so that it can be denoised again): each feature a pair, one per half.
py::dict denoise_input_arrays(DenoiseInput&& in) {
  const int w = in.width, h = in.height;
  py::dict arrays;
  arrays["half_a"] = to_array(std::move(in.half_a), w, h, 3);
  arrays["half_b"] = to_array(std::move(in.half_b), w, h, 3);
  arrays["albedo"] = py::make_tuple(to_array(std::move(in.albedo_a), w, h, 3), to_array(std::move(in.albedo_b), w, h, 3));
  arrays["normal"] = py::make_tuple(to_array(std::move(in.normal_a), w, h, 3), to_array(std::move(in.normal_b), w, h, 3));
  arrays["depth"] = py::make_tuple(to_array(std::move(in.depth_a), w, h, 1), to_array(std::move(in.depth_b), w, h, 1));
  arrays["share_a"] = to_array(std::move(in.share_a), w, h, 1);
  return arrays;
}

// `array`'s values (C-contiguous float32, of the shape the package has checked).
std::vector<float> array_values(const py::array_t<float, py::array::c_style>& array) {
  return std::vector<float>(array.data(), array.data() + array.size());
}

// An (height, width, 3) float32 C-contiguous array (the package converts) into an Image.
Image from_array(const py::array_t<float, py::array::c_style>& array) {
  if (array.ndim() != 3 || array.shape(2) != 3) throw py::value_error("expected an array of shape (height, width, 3)");
  Image image(int(array.shape(1)), int(array.shape(0)));
  std::copy_n(array.data(), image.rgb.size(), image.rgb.begin());
  return image;
}

// The settings and film size a render changes in the description, put back when it ends: a render's
// keywords apply to that render only.
class RequestScope {
 public:
  explicit RequestScope(SceneDesc& desc) : desc_(desc), settings_(desc.settings), film_(desc.film) {}
  ~RequestScope() {
    desc_.settings = settings_;
    desc_.film = film_;
  }
  RequestScope(const RequestScope&) = delete;
  RequestScope& operator=(const RequestScope&) = delete;

 private:
  SceneDesc& desc_;
  RenderSettings settings_;
  FilmDesc film_;
};

// Renders on a worker thread while this one, with the GIL released, wakes 20 times a second to let
// Python run its signal handlers (Ctrl-C raises KeyboardInterrupt here) and call `progress`
// (fraction done, seconds elapsed). An interruption or an exception from `progress` cancels the
// render, which stops within one tile, and is raised once the worker has finished.
py::tuple render_scene(PyScene& scene, const py::dict& keywords, const py::object& progress) {
  RenderRequest request = request_from(keywords);
  std::unique_lock busy(scene.busy, std::try_to_lock);
  if (!busy.owns_lock()) throw py::value_error("this scene is being rendered or edited by another thread");
  RequestScope scope(scene.desc);
  const RenderPlan plan = plan_render(request, scene.desc);
  check_resources(scene.desc);
  RenderOptions options = plan.options();
  std::atomic<bool> cancel{false};
  std::atomic<double> fraction{0};
  options.cancel = &cancel;
  options.progress = false;
  options.progress_fraction = &fraction;

  Image image, noisy;
  std::optional<DenoiseInput> denoised_from;  // with denoise=True: the denoiser's input
  std::map<std::string, std::string> metadata;
  std::exception_ptr failure;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  std::thread worker([&] {
    try {
      Scene built(scene.desc);
      Film film(scene.desc.film.width, scene.desc.film.height);
      // denoise=True: the denoiser's features are collected with the samples (denoise/denoised_render.h).
      std::optional<AovFilm> features;
      if (plan.denoise) {
        features.emplace(film.width(), film.height(), with_denoise_features({}), aov_camera_frame(built.camera()));
        options.aovs = &*features;
      }
      RenderOutcome outcome = render_requested(built, scene.desc.settings, film, plan, options);
      metadata = image_metadata(scene.name, scene.desc.settings, film, outcome, options, 1,
                                outcome.stats.non_finite_samples);
      image = film.mean_image();
      if (features) {
        DenoisedRender denoised = denoise_render(film, *features, &denoised_from.emplace());
        add_denoise_metadata(metadata, denoised.result, denoised.seconds);
        noisy = std::exchange(image, std::move(denoised.result.image));
      }
    } catch (...) {
      failure = std::current_exception();
    }
    std::lock_guard lock(mutex);
    done = true;
    finished.notify_one();
  });

  std::optional<py::error_already_set> python_error;
  const auto start = std::chrono::steady_clock::now();
  {
    py::gil_scoped_release release;
    std::unique_lock lock(mutex);
    while (!finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) {
      if (python_error) continue;  // cancelled: wait for the worker
      lock.unlock();
      {
        py::gil_scoped_acquire acquire;
        try {
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          if (!progress.is_none())
            progress(fraction.load(), std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        } catch (py::error_already_set& e) {
          python_error = std::move(e);
          cancel.store(true);
        }
      }
      lock.lock();
    }
  }
  worker.join();
  if (python_error) throw std::move(*python_error);
  if (failure) std::rethrow_exception(failure);
  py::dict meta;
  for (const auto& [key, value] : metadata) meta[py::str(key)] = value;
  // What only a denoised render has: the raw image and the denoiser's input.
  py::dict denoising;
  if (denoised_from) {
    denoising["noisy"] = to_array(std::move(noisy));
    denoising["input"] = denoise_input_arrays(std::move(*denoised_from));
  }
  return py::make_tuple(to_array(std::move(image)), meta, denoising);
}

// The package's denoise(): arrays it has checked for shape ((height, width, 3) colours, albedos and
// normals; (height, width) shares and depths), in denoise_input_arrays' order with each pair split.
// Returns the denoised image, the metadata a denoised render carries, and the estimated relMSE
// (None where the halves give none).
using DenoiseArray = py::array_t<float, py::array::c_style>;
py::tuple denoise_arrays(const DenoiseArray& half_a, const DenoiseArray& half_b, const DenoiseArray& share_a,
                         const DenoiseArray& albedo_a, const DenoiseArray& albedo_b, const DenoiseArray& normal_a,
                         const DenoiseArray& normal_b, const DenoiseArray& depth_a, const DenoiseArray& depth_b) {
  if (half_a.ndim() != 3) throw py::value_error("half_a: expected an array of shape (height, width, 3)");
  DenoiseInput in;
  in.height = int(half_a.shape(0));
  in.width = int(half_a.shape(1));
  in.half_a = array_values(half_a);
  in.half_b = array_values(half_b);
  in.share_a = array_values(share_a);
  in.albedo_a = array_values(albedo_a);
  in.albedo_b = array_values(albedo_b);
  in.normal_a = array_values(normal_a);
  in.normal_b = array_values(normal_b);
  in.depth_a = array_values(depth_a);
  in.depth_b = array_values(depth_b);
  DenoisedRender denoised;
  {
    py::gil_scoped_release release;
    denoised = denoise_render(in);  // check(): InternalError where a buffer's size is off
  }
  std::map<std::string, std::string> metadata;
  add_denoise_metadata(metadata, denoised.result, denoised.seconds);
  py::dict meta;
  for (const auto& [key, value] : metadata) meta[py::str(key)] = value;
  const ErrorEstimate& error = denoised.result.error;
  return py::make_tuple(to_array(std::move(denoised.result.image)), meta,
                        error.valid ? py::object(py::float_(error.relmse)) : py::object(py::none()));
}

py::object parameter_to_python(const ParameterValue& value) {
  if (const float* f = std::get_if<float>(&value)) return py::float_(*f);
  if (const RGB* c = std::get_if<RGB>(&value)) return py::make_tuple(c->r, c->g, c->b);
  const Matrix4& m = std::get<Matrix4>(value);
  py::array_t<double> out({4, 4});
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out.mutable_at(r, c) = m.m[size_t(r)][size_t(c)];
  return out;
}

// A value of the kind `current` has: a number, three numbers (or one grey), or a 4x4 matrix.
ParameterValue parameter_from_python(const std::string& name, const ParameterValue& current, const py::handle& value) {
  auto kind_error = [&](const char* expected) {
    return py::type_error(name + ": expected " + expected + ", got " + py::str(py::type::of(value).attr("__name__")).cast<std::string>());
  };
  if (py::isinstance<py::str>(value) || py::isinstance<py::bool_>(value)) throw kind_error("a number");
  try {
    if (std::holds_alternative<float>(current)) return py::cast<float>(value);
    if (std::holds_alternative<RGB>(current)) {
      if (!py::isinstance<py::sequence>(value) && !py::isinstance<py::array>(value)) {
        float grey = py::cast<float>(value);
        return RGB(grey);
      }
      auto values = py::cast<std::vector<float>>(value);
      if (values.size() != 3) throw kind_error("three numbers (r, g, b)");
      return RGB(values[0], values[1], values[2]);
    }
    auto rows = py::cast<std::vector<std::vector<double>>>(value);
    Matrix4 m;
    if (rows.size() != 4) throw kind_error("a 4x4 matrix");
    for (size_t r = 0; r < 4; ++r) {
      if (rows[r].size() != 4) throw kind_error("a 4x4 matrix");
      for (size_t c = 0; c < 4; ++c) m.m[r][c] = rows[r][c];
    }
    return m;
  } catch (const py::cast_error&) {
    throw kind_error(std::holds_alternative<float>(current) ? "a number"
                     : std::holds_alternative<RGB>(current) ? "three numbers (r, g, b) or one"
                                                            : "a 4x4 matrix");
  }
}

std::unique_ptr<PyScene> make_scene(SceneDesc&& desc, std::string name) {
  auto scene = std::make_unique<PyScene>();
  scene->desc = std::move(desc);
  scene->name = std::move(name);
  // Read the images now, as the scene's build will (a file that cannot be read is left to the build
  // to report, with the place in the scene that names it).
  auto hold = [&](auto read) {
    try {
      scene->images.push_back(read());
    } catch (const std::exception&) {
    }
  };
  for (const TextureDesc& texture : scene->desc.textures)
    if (const auto* image = std::get_if<ImageTexture>(&texture)) hold([&] { return read_texture_image(*image); });
  for (const LightDesc& light : scene->desc.lights) {
    if (const auto* map = std::get_if<EnvironmentMap>(&light))
      hold([&] { return read_image_shared(map->filename, IntegerEncoding::SRGB); });
    if (const auto* goniometric = std::get_if<GoniometricLight>(&light))
      hold([&] { return read_image_shared(goniometric->filename, IntegerEncoding::SRGB); });
  }
  return scene;
}

}  // namespace

PYBIND11_MODULE(_candela, m) {
  m.doc() = "The compiled half of the candela package; import candela instead.";
  m.attr("version") = CANDELA_VERSION;

  m.def("set_exception_types", [](py::object scene_error, py::object usage_error) {
    g_scene_error = scene_error.release();
    g_usage_error = usage_error.release();
  });
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const SceneError& e) {
      PyErr_SetString(g_scene_error.ptr(), e.what());
    } catch (const FileContentError& e) {
      PyErr_SetString(g_scene_error.ptr(), e.what());
    } catch (const UnknownParameterError& e) {  // scene parameters: an unknown name
      PyErr_SetString(PyExc_KeyError, e.what());
    } catch (const UsageError& e) {
      PyErr_SetString(g_usage_error.ptr(), e.what());
    } catch (const OutputError& e) {  // an image that cannot be written (docs/python.md)
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }  // InternalError and other exceptions: pybind11's own translation (RuntimeError for most)
  });

  py::class_<PyScene>(m, "Scene")
      .def_property_readonly("name", [](const PyScene& s) { return s.name; })
      .def_property_readonly("resolution", [](const PyScene& s) { return py::make_tuple(s.desc.film.width, s.desc.film.height); })
      .def("settings",
           [](const PyScene& s) {
             const RenderSettings& r = s.desc.settings;
             py::dict d;
             d["spp"] = r.spp;
             d["max_depth"] = r.max_depth;
             d["seed"] = r.seed;
             d["integrator"] = r.integrator;
             d["transport"] = r.spectral ? "spectral" : "rgb";
             d["resolution"] = py::make_tuple(s.desc.film.width, s.desc.film.height);
             return d;
           })
      .def("parameters",
           [](PyScene& s) {
             std::lock_guard lock(s.busy);
             py::list out;
             for (const SceneParameter& p : scene_parameters(s.desc))
               out.append(py::make_tuple(p.name, parameter_to_python(p.value), p.range));
             return out;
           })
      .def("parameter",
           [](PyScene& s, const std::string& name) {
             std::lock_guard lock(s.busy);
             return parameter_to_python(scene_parameter(s.desc, name));
           })
      .def("set_parameter",
           [](PyScene& s, const std::string& name, const py::handle& value) {
             std::unique_lock busy(s.busy, std::try_to_lock);
             if (!busy.owns_lock()) throw py::value_error("this scene is being rendered by another thread");
             set_scene_parameter(s.desc, name, parameter_from_python(name, scene_parameter(s.desc, name), value));
           })
      .def("to_json", [](PyScene& s) {
        std::lock_guard lock(s.busy);
        return scene_to_json(s.desc);
      });

  m.def("load_file", [](const std::string& path, const std::map<std::string, std::string>& parameters) {
    Warnings warnings;
    SceneDesc desc;
    {
      py::gil_scoped_release release;
      // The readers' warnings come back to the package, which warns with them.
      desc = read_scene_file(path, SceneReadOptions{parameters, &warnings});
    }
    return py::make_tuple(make_scene(std::move(desc), path), warnings.lines());
  });
  m.def("load_json", [](const std::string& text, const std::string& name, const std::string& base_dir) {
    return make_scene(read_json_scene(text, name, base_dir), name);
  });
  m.def("builtin_scene", [] {
    return make_scene(read_json_scene(builtin_scene_json(), "<built-in cornell-box.json>", "."), "<built-in cornell-box.json>");
  });
  m.def("render_keywords", &request_kinds);
  // The option table itself (keyword, flag, help, whether render() takes it), for tests and help.
  m.def("render_options", [] {
    py::list options;
    for (const RenderOption& option : render_options())
      options.append(py::make_tuple(option.name, option.flag(), option.help, option.python));
    return options;
  });
  m.def("render", &render_scene);
  m.def("denoise", &denoise_arrays);
  m.def("write_image", [](const std::string& path, const py::array_t<float, py::array::c_style>& array,
                          const std::map<std::string, std::string>& metadata) {
    write_image(path, from_array(array), metadata);
  });
  m.def("read_image", [](const std::string& path) { return to_array(read_image(path)); });
  m.def("read_image_metadata", [](const std::string& path) { return read_image_metadata(path); });
  m.def("encode_png", [](const py::array_t<float, py::array::c_style>& array) {
    std::vector<unsigned char> bytes = encode_png(from_array(array));
    return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  });
}
