#pragma once
/// \file The docstrings of the module's functions. Each begins with the function's signature
/// followed by "--" (CPython's text signature), which `help()` and `inspect.signature` read:
/// the functions take (*args, **kwargs) and bind them themselves (arguments.h), so pybind11's
/// generated signatures are off.

namespace amalgam::python::doc {

inline constexpr const char* kRender =
    "render(self, /, *, width=512, height=512, spp=4, renderer='scale-sensitive', "
    "opacity='stochastic', level=None, footprint=None, order='sorted', seed=0, threads=0, "
    "sampler='independent', camera=None, eye=None, look_at=None, up=None, fov=None, "
    "light_samples=None, tracer='amalgam', progress=None)\n--\n\n"
    "Renders the scene's camera view; the options are the CLI's (docs/cli.md). camera=\n"
    "(name or index), eye=, look_at=, up= (x, y, z) and fov= (degrees) change the view\n"
    "of this render only, as --camera, --eye, --look-at, --up and --fov do, starting from\n"
    "the view `load` chose; the scene is not rebuilt or rebaked. light_samples= is\n"
    "--light-samples (shadow rays per sized light). tracer='embree' renders at full\n"
    "detail with Intel Embree 3 (--tracer embree; its BVHs are built on first use and\n"
    "kept by the scene). The same seed gives the same image as\n"
    "`amalgam render ... --out x.pfm`, bit for bit, on any number of threads. The GIL is\n"
    "released. Ctrl-C (KeyboardInterrupt) stops the render at its next tile; the\n"
    "exception's `partial` attribute (and scene.last_result) holds the completed samples.\n"
    "progress=f calls f(spp_done, spp) on this thread as passes of samples complete (and\n"
    "once at the end); an exception it raises stops the render as Ctrl-C does. Raises\n"
    "TypeError on an unknown keyword or a value of the wrong type, ValueError on a bad\n"
    "value (e.g. seed=-1, or level beyond l_max).";

inline constexpr const char* kTrace =
    "trace(self, /, origin=None, direction=None, *, width=512, height=512, "
    "renderer='scale-sensitive', opacity='stochastic', level=None, footprint=None, "
    "order='sorted', seed=0, tracer='amalgam')\n--\n\n"
    "Traces one primary ray with its shadow rays (`amalgam trace`): by default the\n"
    "camera's centre ray. Returns the CLI's trace JSON as a dict: 'hit' (None or t,\n"
    "object {kind, id, level}, point), 'colour', 'rays', 'tests', ...";

inline constexpr const char* kLoad =
    "load(scene, *, camera=None, eye=None, look_at=None, up=None, fov=None, "
    "light_samples=None, volumetric=False, smooth_normals=False, **params)\n--\n\n"
    "Loads, builds and bakes a scene: 'builtin:NAME' with its parameters as keyword\n"
    "arguments (the CLI's --set key=value, e.g. load('builtin:line', n=4)), a scene .json\n"
    "or a mesh path (str or os.PathLike), or a dict holding what a scene .json holds\n"
    "(relative mesh paths in it are relative to the current directory). The view keywords\n"
    "camera= (name or index), eye=, look_at=, up= (x, y, z) and fov= (degrees) are the\n"
    "CLI's --camera, --eye, --look-at, --up, --fov. volumetric=True loads it for\n"
    "renderer='volumetric' (every mesh an object with its volumetric amalgams baked);\n"
    "smooth_normals=True is --smooth-normals (meshes without vertex normals get smooth\n"
    "ones). Raises ValueError with the CLI's message on bad input, TypeError on a keyword\n"
    "that is neither one of these nor a parameter of the builtin scene.";

inline constexpr const char* kSaveImage =
    "save_image(path, image)\n--\n\n"
    "Writes an H x W x 3 linear RGB image (an array or a RenderResult) as `render --out`\n"
    "does, by the extension of `path` (str or os.PathLike): .png (8-bit sRGB), .exr\n"
    "(float32), .pfm (float32). Raises ValueError on a bad image or extension,\n"
    "RuntimeError when writing fails.";

inline constexpr const char* kSave =
    "save(self, /, path)\n--\n\n"
    "Writes the image as amalgam.save_image(path, self) does.";

inline constexpr const char* kArray =
    "__array__(self, /, dtype=None, copy=None)\n--\n\n"
    "The image (float32 H x W x 3) for numpy.asarray(result): the `image` array itself,\n"
    "no copy, unless dtype= asks for another type or copy=True. copy=False with a dtype\n"
    "that needs a copy raises ValueError (NumPy 2's protocol).";

inline constexpr const char* kToSrgb =
    "to_srgb(image)\n--\n\n"
    "Linear RGB (an array or a RenderResult) encoded as the PNG output stores it: clamped\n"
    "to [0, 1], the sRGB transfer function (IEC 61966-2-1), rounded to 8 bits; uint8\n"
    "H x W x 3.";

inline constexpr const char* kCompare =
    "compare(a, b)\n--\n\n"
    "Image metrics of `amalgam compare` for two H x W x 3 images (arrays or RenderResults),\n"
    "b the reference, as a dict: width, height, rmse, psnr_db, ssim, mean_abs_error,\n"
    "max_abs_error, rel_mse (the names of `amalgam compare --json`).";

inline constexpr const char* kExperiment =
    "experiment(name, quick=True, threads=0, frame=False)\n--\n\n"
    "Runs one of the paper's analyses (`amalgam experiment NAME`) and returns its table\n"
    "(the CSV's rows) as a list of dicts keyed by column, or with frame=True as a pandas\n"
    "DataFrame with the CSV's columns in order (ImportError when pandas is not installed).\n"
    "The GIL is released.";

inline constexpr const char* kExperimentNames =
    "experiment_names()\n--\n\n"
    "The experiment names in report order.";

}  // namespace amalgam::python::doc
