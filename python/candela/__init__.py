"""candela, a physically based Monte Carlo path tracer, from Python.

    import candela
    scene = candela.load_file("scene.xml", spp=64)      # any format candela reads; Mitsuba $parameters
    image = candela.render(scene, spp=64, seed=1)       # a float32 NumPy array (height, width, 3)
    params = candela.traverse(scene)                    # the editable parameters, by name
    params["materials.red.reflectance"] = (0.8, 0.1, 0.1)
    image = candela.render(scene)                       # again, without reading any file
    image.write("out.exr")                              # with candela's metadata

render()'s keywords are the command line's flags with '_' for '-' (docs/cli.md), checked the same
way; docs/python.md walks through the rest.
"""
from __future__ import annotations

import collections.abc
import importlib.machinery
import json
import numbers
import operator
import os
import platform
import re
import shlex
import sys
import time
import warnings


def _same_file(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


def _interpreter_error(problem: str, build_info, numpy_missing: bool = False) -> ImportError:
    """An ImportError that names the interpreter the package was built for, the one running, and the
    commands that build it for the one running (docs/python.md, "Building for your interpreter")."""
    this = sys.executable or "python3"
    source = getattr(build_info, "source_dir", None) or "<candela's source directory>"
    build = getattr(build_info, "build_dir", None) or os.path.join(source, "build")
    if build_info is not None:
        built_for = f"{build_info.executable} (Python {build_info.version})"
    else:
        built_for = "unknown (candela/_build_info.py, which CMake writes beside the package, is missing)"
    q = shlex.quote
    lines = [f"candela cannot be imported: {problem}",
             f"  built for:   {built_for}",
             f"  running now: {this} (Python {platform.python_version()})"]
    same = build_info is not None and _same_file(this, build_info.executable)
    if same and numpy_missing:
        debian = " or, for Debian's /usr/bin/python3, apt-get install python3-numpy" if this.startswith("/usr/bin/") else ""
        lines.append(f"Install NumPy for it: {q(this)} -m pip install numpy{debian}.")
    elif same:
        lines.append("Rebuild it for this interpreter:")
    else:
        lines.append(f"Build candela for the interpreter running now (it needs NumPy: {q(this)} -m pip install numpy):")
    if not (same and numpy_missing):
        lines += [f"  cmake -S {q(source)} -B {q(build)} -DPython_EXECUTABLE={q(this)}",
                  f"  cmake --build {q(build)}",
                  f"then run with PYTHONPATH={q(os.path.join(build, 'python'))}, or install it into this "
                  f"interpreter's site-packages with: cmake --install {q(build)}"]
    if build_info is not None and not same:
        lines.append(f"Or run the interpreter it was built for: {build_info.executable}")
    return ImportError("\n".join(lines), name=__name__)


def _check_interpreter():
    """Raises _interpreter_error where the extension module cannot load in this interpreter (another
    Python version or ABI than the build's), before an import fails with a message that says less."""
    try:
        from . import _build_info
    except ImportError:
        return None
    built = tuple(int(part) for part in _build_info.version.split(".")[:2])
    abi_tag = _build_info.extension[len("_candela"):]  # e.g. .cpython-311-x86_64-linux-gnu.so
    if built != sys.version_info[:2]:
        raise _interpreter_error(f"its extension module {_build_info.extension} is for Python "
                                 f"{built[0]}.{built[1]}, and this interpreter is Python "
                                 f"{sys.version_info[0]}.{sys.version_info[1]}", _build_info) from None
    if abi_tag not in importlib.machinery.EXTENSION_SUFFIXES:
        raise _interpreter_error(f"its extension module {_build_info.extension} is not for this interpreter's ABI "
                                 f"(it loads {', '.join(importlib.machinery.EXTENSION_SUFFIXES)})",
                                 _build_info) from None
    return _build_info


_build_info = _check_interpreter()
try:
    import numpy as np
except ImportError as e:
    raise _interpreter_error(f"NumPy is not installed for this interpreter ({e})", _build_info, numpy_missing=True) from e
try:
    from . import _candela
except ImportError as e:
    raise _interpreter_error(f"its extension module _candela does not load ({e})", _build_info) from e

__version__ = _candela.version
__all__ = ["Image", "Scene", "SceneError", "SceneParameters", "SceneWarning", "UsageError", "builtin_scene",
           "denoise", "load_dict", "load_file", "read_image", "render", "render_keywords", "traverse", "write_image"]


class SceneError(ValueError):
    """A scene that cannot be read or rendered: a malformed or missing file, a bad value.

    The message names the place, as the command line's does; the attributes hold its parts:
    ``file``, ``line`` and ``column`` (0 where unknown) and ``pointer``, the JSON pointer of the
    offending value in a JSON scene or a dict given to load_dict ('' where none).
    """

    _PLACE = re.compile(r"^(?P<file>.*?)(?::(?P<line>\d+)(?::(?P<column>\d+))?)?(?:: at (?P<pointer>/[^:]*))?: ",
                        re.S)

    def __init__(self, message: str):
        super().__init__(message)
        place = self._PLACE.match(message)
        self.file = place["file"] if place else ""
        self.line = int(place["line"]) if place and place["line"] else 0
        self.column = int(place["column"]) if place and place["column"] else 0
        self.pointer = (place["pointer"] or "") if place else ""


class UsageError(ValueError):
    """Render settings the renderer refuses: a value out of range, an unknown integrator or sampler,
    settings that exclude each other. The message names the keyword."""


class SceneWarning(UserWarning):
    """A warning from a scene reader (a Mitsuba plugin parameter candela ignores, for example)."""


_candela.set_exception_types(SceneError, UsageError)


def _keyword_message(message: str) -> str:
    # The library names the command line's flags ("--max-depth"); here they are keywords.
    return re.sub(r"--([a-z][a-z0-9-]*)", lambda m: m.group(1).replace("-", "_"), message)


class Scene:
    """A loaded scene: what load_file and load_dict return and render takes.

    Its files are read once, when it is loaded; renders and edits (traverse) work on what was read.
    """

    def __init__(self, native):
        self._native = native

    @property
    def name(self) -> str:
        """The file it was read from, or '<dict>'."""
        return self._native.name

    @property
    def resolution(self) -> tuple[int, int]:
        """(width, height) as the scene sets it (render(resolution=...) overrides it per render)."""
        return self._native.resolution

    def settings(self) -> dict:
        """The render settings the scene itself gives (spp, max_depth, seed, integrator, transport,
        resolution): what render() uses where no keyword overrides them."""
        return self._native.settings()

    def to_json(self) -> str:
        """The scene, edits included, in candela's JSON format (docs/scene-format.md)."""
        return self._native.to_json()

    def to_dict(self) -> dict:
        """to_json() as a dict, which load_dict reads back to the same scene."""
        return json.loads(self.to_json())

    def __repr__(self) -> str:
        width, height = self.resolution
        return f"<candela.Scene {self.name!r} {width}x{height}>"


class SceneParameters(collections.abc.MutableMapping):
    """The editable parameters of a scene by name, a live view (Mitsuba's traverse()).

    Numbers are floats, colours (r, g, b) tuples (a single number sets grey), transforms 4x4 NumPy
    arrays (row-major, column vectors: world = M @ local). Setting one checks its kind and range and
    changes the scene for every later render; no parameter can be added or removed.
    """

    def __init__(self, scene: Scene):
        self._scene = scene

    def _entries(self):
        return self._scene._native.parameters()

    def __getitem__(self, name: str):
        return self._scene._native.parameter(name)  # KeyError naming the nearest names

    def __setitem__(self, name: str, value) -> None:
        if isinstance(value, np.ndarray):
            value = value.tolist()
        self._scene._native.set_parameter(name, value)

    def __delitem__(self, name: str) -> None:
        raise TypeError("scene parameters cannot be removed, only changed")

    def __iter__(self):
        return iter([name for name, _, _ in self._entries()])

    def __len__(self) -> int:
        return len(self._entries())

    def range(self, name: str) -> str:
        """What the parameter accepts, e.g. '0 < fov < 180'."""
        for entry_name, _, accepted in self._entries():
            if entry_name == name:
                return accepted
        raise KeyError(f"no scene parameter {name!r}")

    def __repr__(self) -> str:
        lines = [f"SceneParameters of {self._scene.name!r}:"]
        for name, value, accepted in self._entries():
            if isinstance(value, np.ndarray):
                shown = "4x4 matrix " + np.array2string(value, precision=4, separator=", ").replace("\n", "")
            elif isinstance(value, tuple):
                shown = "(" + ", ".join(f"{v:.6g}" for v in value) + ")"
            else:
                shown = f"{value:.6g}"
            lines.append(f"  {name} = {shown}    [{accepted}]")
        return "\n".join(lines)


def traverse(scene: Scene) -> SceneParameters:
    """The editable parameters of `scene` by name (see SceneParameters)."""
    if not isinstance(scene, Scene):
        raise TypeError(f"traverse() takes a candela.Scene, got {type(scene).__name__}")
    return SceneParameters(scene)


def _mitsuba_parameter_text(name: str, value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, str):
        return value
    if isinstance(value, numbers.Real):
        return repr(int(value)) if isinstance(value, numbers.Integral) else repr(float(value))
    if isinstance(value, (list, tuple, np.ndarray)) and all(isinstance(v, numbers.Real) for v in value):
        return ", ".join(repr(float(v)) for v in value)
    raise TypeError(f"load_file(): ${name} must be a string, a number or a sequence of numbers, got {type(value).__name__}")


def load_file(path, **parameters) -> Scene:
    """Reads a scene file in any format candela reads, chosen by extension: .json (candela's own),
    .pbrt (pbrt-v4), .xml (Mitsuba 3), .gltf/.glb, .obj, .ply (as candela's command line does).

    Keyword arguments set a Mitsuba scene's $parameters, over its <default> tags (Mitsuba's -D
    name=value): load_file("cbox.xml", spp=64, res=256). Raises SceneError naming the file and line.
    """
    path = os.fspath(path)
    if not isinstance(path, str):
        raise TypeError(f"load_file(): path must be a string or path, got {type(path).__name__}")
    if parameters and not path.lower().endswith(".xml"):
        raise TypeError(f"load_file(): keyword arguments set a Mitsuba scene's $parameters; {path!r} is not a "
                        "Mitsuba .xml file (render() takes the render settings)")
    values = {name: _mitsuba_parameter_text(name, value) for name, value in parameters.items()}
    native, reader_warnings = _candela.load_file(path, values)
    for warning in reader_warnings:
        warnings.warn(warning, SceneWarning, stacklevel=2)
    return Scene(native)


def _json_value(value):
    # NumPy arrays and scalars in a scene dict become plain JSON values.
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"a {type(value).__name__} cannot go in a scene (use numbers, strings, lists and dicts)")


def load_dict(scene: collections.abc.Mapping, base_dir=None) -> Scene:
    """Reads a scene given as a dict in candela's JSON scene format (docs/scene-format.md), with the
    JSON reader's checks and messages; a SceneError's ``pointer`` names the offending entry, e.g.
    '/shapes/3/radius'. Relative file names (meshes, textures) are resolved against `base_dir`
    (default: the working directory)."""
    if not isinstance(scene, collections.abc.Mapping):
        raise TypeError(f"load_dict() takes a dict in candela's JSON scene format, got {type(scene).__name__}")
    try:
        text = json.dumps(scene, allow_nan=False, default=_json_value)
    except ValueError as e:  # NaN or infinity
        raise SceneError(f"<dict>: {e} (NaN and infinity are not scene values)") from None
    try:
        native = _candela.load_json(text, "<dict>", os.fspath(base_dir) if base_dir is not None else os.getcwd())
    except SceneError as e:
        # Lines and columns of the JSON text made from the dict mean nothing to its author; the
        # pointer says where.
        raise SceneError(re.sub(r"^<dict>:\d+(:\d+)?", "<dict>", str(e))) from None
    return Scene(native)


def builtin_scene() -> Scene:
    """The Cornell box that `candela` renders with no arguments (scenes/cornell-box.json)."""
    return Scene(_candela.builtin_scene())


class Image(np.ndarray):
    """A rendered image: a float32 NumPy array (height, width, 3) of linear RGB with the render's
    metadata (``metadata``: the EXR attributes the command line writes, such as candela:spp and
    candela:relmse_estimate). Jupyter shows it inline, tone-mapped to sRGB.

    The image of render(..., denoise=True) is the denoised one; ``noisy`` holds the raw render (an
    Image with the same metadata) and ``denoise_input`` the denoiser's input (a dict of the keyword
    arguments of denoise(): half_a, half_b, share_a, and albedo, normal and depth as pairs, half A's
    and half B's). Both are None for other
    images, and for arrays made from this one (a slice, a sum)."""

    def __array_finalize__(self, obj):
        self.metadata = dict(getattr(obj, "metadata", {}) or {})
        self.noisy = None
        self.denoise_input = None

    def _repr_png_(self):
        if self.ndim != 3 or self.shape[2] != 3 or self.size == 0:
            return None
        return _candela.encode_png(np.ascontiguousarray(self, dtype=np.float32))

    def write(self, path) -> None:
        """write_image(path, self, self.metadata)."""
        write_image(path, self, self.metadata)


def _as_rgb(array) -> np.ndarray:
    rgb = np.asarray(array, dtype=np.float32)
    if rgb.ndim == 2:
        rgb = np.repeat(rgb[:, :, None], 3, axis=2)
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.shape[0] < 1 or rgb.shape[1] < 1:
        raise ValueError(f"expected an image array of shape (height, width, 3) or (height, width), got {rgb.shape}")
    return np.ascontiguousarray(rgb)


def write_image(path, image, metadata: dict | None = None) -> None:
    """Writes an array (height, width, 3) or (height, width) of linear values: .exr (float, with
    `metadata` as string attributes), .pfm (float) or .png (sRGB 8-bit). Written atomically: an
    existing file is never left half-written."""
    if metadata is None:
        metadata = getattr(image, "metadata", {}) or {}
    _candela.write_image(os.fspath(path), _as_rgb(image), {str(k): str(v) for k, v in metadata.items()})


def read_image(path) -> Image:
    """Reads any image OpenImageIO reads as linear float RGB, with its metadata."""
    path = os.fspath(path)
    image = _candela.read_image(path).view(Image)
    image.metadata = _candela.read_image_metadata(path)
    return image


def render_keywords() -> dict:
    """render()'s keywords and their kinds ('int', 'uint', 'float', 'str', 'bool')."""
    return dict(_candela.render_keywords())


def _checked_keywords(keywords: dict) -> dict:
    kinds = _candela.render_keywords()
    request = {}
    for name, value in keywords.items():
        kind = kinds.get(name)
        if kind is None:
            raise TypeError(f"render() got an unexpected keyword argument {name!r} (known: {', '.join(sorted(kinds))}, progress)")
        if value is None:  # the scene's own value
            continue
        if name == "resolution" and not isinstance(value, str):
            try:
                width, height = (operator.index(v) for v in value)
            except (TypeError, ValueError):
                raise TypeError(f"render(): resolution must be (width, height) or 'WIDTHxHEIGHT', got {value!r}") from None
            value = f"{width}x{height}"
        elif name == "time_limit" and isinstance(value, numbers.Real) and not isinstance(value, bool):
            value = f"{float(value):.9f}".rstrip("0").rstrip(".") if value > 0 else str(value)
        elif kind in ("int", "uint"):
            if isinstance(value, (bool, np.bool_)):
                raise TypeError(f"render(): {name} must be an integer, got bool")
            try:
                value = operator.index(value)
            except TypeError:
                raise TypeError(f"render(): {name} must be an integer, got {type(value).__name__}") from None
            lo, hi = (-2**31, 2**31 - 1) if kind == "int" else (0, 2**64 - 1)
            if not lo <= value <= hi:
                raise UsageError(f"{name}: {value} is out of range")
        elif kind == "float":
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
                raise TypeError(f"render(): {name} must be a number, got {type(value).__name__}")
            value = float(value)
        elif kind == "bool":
            if not isinstance(value, (bool, np.bool_)):
                raise TypeError(f"render(): {name} must be True or False, got {type(value).__name__}")
            value = bool(value)
        elif not isinstance(value, str):
            raise TypeError(f"render(): {name} must be a string, got {type(value).__name__}")
        request[name] = value
    return request


class _TextBar:
    """A one-line progress bar with elapsed time and ETA on a text stream (a terminal or a notebook)."""

    def __init__(self, stream):
        self.stream = stream
        self.last = -1.0

    def __call__(self, fraction: float, elapsed: float) -> None:
        now = time.monotonic()
        if now - self.last < 0.2 and fraction < 1:
            return
        self.last = now
        eta = elapsed * (1 - fraction) / fraction if fraction > 0 else float("nan")
        filled = int(fraction * 40)
        bar = "=" * filled + (">" + " " * (39 - filled) if filled < 40 else "")
        eta_text = f"{eta:6.1f} s" if eta == eta else "     ? s"
        self.stream.write(f"\r[{bar}] {100 * fraction:5.1f}%  elapsed {elapsed:6.1f} s  ETA {eta_text}")
        self.stream.flush()

    def close(self) -> None:
        if self.last >= 0:
            self.stream.write("\n")
            self.stream.flush()


def render(scene: Scene, *, progress=None, **keywords) -> Image:
    """Renders `scene` and returns the image as an Image (a float32 NumPy array (height, width, 3)).

    Keywords are the command line's render flags with '_' for '-' (docs/cli.md), checked as it
    checks them, and apply to this render only: spp, seed, integrator ('path', 'bdpt', 'mlt',
    'auto'), resolution ((w, h) or 'WxH'), threads, max_depth, sampler, filter, transport
    ('rgb'/'spectral'), light_selection, direction_sampling, shadow_rays, no_mis, clamp, bvh, rr_start_depth,
    adaptive_threshold, adaptive_spp, adaptive_batch, max_spp, time_limit (seconds or '10m'),
    target_error, estimate_error, denoise, mlt_*; see render_keywords(). The same settings give the same
    bytes as `candela render`, whatever the thread count.

    denoise=True returns the denoised image (docs/denoising.md), with the raw render as its ``noisy``
    attribute and the denoiser's input as ``denoise_input`` (see Image); its metadata holds the raw
    image's estimated relMSE (candela:relmse_estimate, which target_error also reads) and the denoised
    one's (candela:denoised_relmse_estimate and candela:denoised_relmse_interval95).

    progress: None (a text bar on stderr when it is a terminal), True, False, or a callable
    progress(fraction_done, seconds_elapsed), called about 20 times a second from this thread.

    The GIL is released while rendering; Ctrl-C (KeyboardInterrupt) stops the render within one
    tile and is raised, as is an exception from the progress callable.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"render() takes a candela.Scene (from load_file or load_dict), got {type(scene).__name__}")
    request = _checked_keywords(keywords)
    if progress is None:
        progress = sys.stderr is not None and sys.stderr.isatty()
    bar = None
    if progress is True:
        bar = _TextBar(sys.stderr)
        callback = bar
    elif progress is False:
        callback = None
    elif callable(progress):
        callback = progress
    else:
        raise TypeError(f"render(): progress must be None, True, False or a callable, got {type(progress).__name__}")
    try:
        result = _candela.render(scene._native, request, callback)
    except UsageError as e:
        raise UsageError(_keyword_message(str(e))) from None
    finally:
        if bar is not None:
            bar.close()
    array, metadata, denoising = result
    image = array.view(Image)
    image.metadata = metadata
    if denoising:
        image.noisy = denoising["noisy"].view(Image)
        image.noisy.metadata = dict(metadata)
        image.denoise_input = dict(denoising["input"])
    if "candela:non_finite_samples" in metadata:
        warnings.warn(f"{metadata['candela:non_finite_samples']} samples were NaN or infinite and counted as black",
                      RuntimeWarning, stacklevel=2)
    return image



def _denoise_array(name: str, value, shape: tuple) -> np.ndarray:
    try:
        array = np.ascontiguousarray(value, dtype=np.float32)
    except (TypeError, ValueError) as e:
        raise TypeError(f"denoise(): {name} must be an array of numbers ({e})") from None
    if array.shape != shape:
        raise ValueError(f"denoise(): {name} must have shape {shape}, got {array.shape}")
    return array


def _denoise_pair(name: str, value, shape: tuple) -> tuple:
    # One array for both halves, or a pair (half A's, half B's).
    if isinstance(value, (tuple, list)) and len(value) == 2 and not np.isscalar(value[0]) \
            and np.ndim(value[0]) == len(shape):
        return _denoise_array(name + "[0]", value[0], shape), _denoise_array(name + "[1]", value[1], shape)
    array = _denoise_array(name, value, shape)
    return array, array


def denoise(image_or_half_a, half_b=None, albedo=None, normal=None, depth=None, share_a=None):
    """Denoises a render (docs/denoising.md) and returns (image, relmse_estimate): the denoised image
    as an Image, and its estimated relMSE (eps 0.01), or None where the halves give no estimate.

        denoised, relmse = candela.denoise(candela.render(scene, denoise=True))   # again: the same bytes
        denoised, relmse = candela.denoise(half_a, half_b, albedo, normal, depth)  # from arrays

    Takes an Image from render(..., denoise=True) (its ``denoise_input``), or arrays: half_a and
    half_b (height, width, 3), two independent estimates of each pixel (the two halves of its
    samples); the first hit's features albedo and normal (height, width, 3) and depth (height,
    width; 1e10 where no sample hit), each one array or a pair (half A's, half B's); share_a (height,
    width), half A's share of each pixel's weight (the raw image is share_a * half_a + (1 - share_a)
    * half_b; default 0.5). Each half's own features keep the error estimate honest: features shared
    by the halves tie each half's fit to the other's noise. The image's metadata is the given
    Image's, if any, with candela:denoised, candela:denoised_relmse_estimate,
    candela:denoised_relmse_interval95 and candela:denoise_seconds. Deterministic: the same input
    gives the same bytes whatever the thread count.
    """
    metadata = {}
    if isinstance(image_or_half_a, Image) and half_b is None:
        if image_or_half_a.denoise_input is None:
            raise ValueError("denoise(): this image carries no denoiser input: render with denoise=True, or pass the "
                             "arrays (half_a, half_b, albedo, normal, depth)")
        given = dict(image_or_half_a.denoise_input)
        metadata = dict(image_or_half_a.metadata)
    else:
        given = {"half_a": image_or_half_a, "half_b": half_b, "albedo": albedo, "normal": normal, "depth": depth,
                 "share_a": share_a}
        missing = [name for name in ("half_a", "half_b", "albedo", "normal", "depth") if given[name] is None]
        if missing:
            raise TypeError(f"denoise() takes an Image from render(..., denoise=True), or the arrays half_a, half_b, "
                            f"albedo, normal and depth: missing {', '.join(missing)}")
    half_a = np.asarray(given["half_a"])
    if half_a.ndim != 3 or half_a.shape[2] != 3 or half_a.shape[0] < 1 or half_a.shape[1] < 1:
        raise ValueError(f"denoise(): half_a must have shape (height, width, 3), got {half_a.shape}")
    rgb, plane = half_a.shape, half_a.shape[:2]
    halves = {name: _denoise_array(name, given[name], rgb) for name in ("half_a", "half_b")}
    share = given.get("share_a")
    halves["share_a"] = np.full(plane, 0.5, dtype=np.float32) if share is None else _denoise_array("share_a", share, plane)
    features = {"albedo": _denoise_pair("albedo", given["albedo"], rgb),
                "normal": _denoise_pair("normal", given["normal"], rgb),
                "depth": _denoise_pair("depth", given["depth"], plane)}
    for name, array in [*halves.items(), ("albedo", features["albedo"][0]), ("albedo", features["albedo"][1]),
                        ("normal", features["normal"][0]), ("normal", features["normal"][1])]:
        if not np.all(np.isfinite(array)):
            raise ValueError(f"denoise(): {name} has NaN or infinite values")
    if not np.all((halves["share_a"] >= 0) & (halves["share_a"] <= 1)):
        raise ValueError("denoise(): share_a must be within [0, 1]")
    if any(np.any(np.isnan(d)) for d in features["depth"]):
        raise ValueError("denoise(): depth has NaN values (use 1e10 where no sample hit)")
    array, denoise_metadata, relmse = _candela.denoise(halves["half_a"], halves["half_b"], halves["share_a"],
                                                       *features["albedo"], *features["normal"], *features["depth"])
    image = array.view(Image)
    image.metadata = {**metadata, **denoise_metadata}
    return image, relmse
