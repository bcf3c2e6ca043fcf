"""Type stub of the amalgam module (python/amalgam_module.cpp; docs/python.md)."""

import os
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

# A path argument: str, bytes or os.PathLike (pathlib.Path), as open() takes it.
_StrPath = Union[str, bytes, os.PathLike[str], os.PathLike[bytes]]

__version__: str
has_embree: bool  # whether tracer="embree" is available in this build

class RenderResult:
    """The outputs of Scene.render. Pixel (x, y) is [y, x], row 0 at the top."""

    image: npt.NDArray[np.float32]  # H x W x 3, linear RGB (the CLI's PFM image)
    cost: npt.NDArray[np.float64]  # H x W, exact intersection tests per pixel / spp
    tests: npt.NDArray[np.uint64]  # H x W, exact tests per pixel, total over its samples
    depth: npt.NDArray[np.float32]  # H x W, mean primary-hit distance (inf: none)
    level: npt.NDArray[np.float32]  # H x W, rendered level (-2 primitives, -1 nothing)
    normal: npt.NDArray[np.float32]  # H x W x 3
    albedo: npt.NDArray[np.float32]  # H x W x 3
    stats: dict[str, Any]  # the CLI's stats JSON
    width: int
    height: int
    spp: int  # samples per pixel the image holds
    spp_requested: int
    interrupted: bool
    seconds: float
    def save(self, path: _StrPath) -> None:
        """Writes the image as `render --out` does: .png (8-bit sRGB), .exr or .pfm."""
    def __array__(
        self, dtype: Optional[npt.DTypeLike] = None, copy: Optional[bool] = None
    ) -> npt.NDArray[Any]:
        """numpy.asarray(result): the image itself (no copy) unless dtype or copy=True ask
        for one; copy=False raises ValueError where a copy is needed."""

class Scene:
    """A loaded scene: its built, baked hierarchy, reused by every render."""

    @property
    def last_result(self) -> Optional[RenderResult]: ...
    @property
    def levels(self) -> int: ...
    @property
    def name(self) -> str: ...
    @property
    def warnings(self) -> list[str]: ...
    def render(
        self,
        /,
        *,
        width: int = 512,
        height: int = 512,
        spp: int = 4,
        renderer: str = "scale-sensitive",  # or "traditional"
        opacity: str = "stochastic",  # or "deterministic"
        level: Optional[int] = None,
        footprint: Optional[float] = None,
        order: str = "sorted",  # or "unsorted"
        seed: int = 0,
        threads: int = 0,  # 0: all cores
        sampler: str = "independent",  # or "stratified"
        camera: Optional[Union[str, int]] = None,
        eye: Optional[Sequence[float]] = None,
        look_at: Optional[Sequence[float]] = None,
        up: Optional[Sequence[float]] = None,
        fov: Optional[float] = None,
        light_samples: Optional[int] = None,
        tracer: str = "amalgam",  # or "embree": full detail in Intel Embree 3
        progress: Optional[Callable[[int, int], None]] = None,  # f(spp_done, spp)
    ) -> RenderResult:
        """Renders the camera view (camera=, eye=, look_at=, up=, fov= change it for this
        render only, from the view `load` chose); KeyboardInterrupt carries `.partial`."""
    def trace(
        self,
        /,
        origin: Optional[Sequence[float]] = None,
        direction: Optional[Sequence[float]] = None,
        *,
        width: int = 512,
        height: int = 512,
        renderer: str = "scale-sensitive",
        opacity: str = "stochastic",
        level: Optional[int] = None,
        footprint: Optional[float] = None,
        order: str = "sorted",
        seed: int = 0,
        tracer: str = "amalgam",  # or "embree"
    ) -> dict[str, Any]:
        """One primary ray with its shadow rays: 'hit', 'colour' and the counts."""

def load(
    scene: Union[_StrPath, dict[str, Any]],  # a path, "builtin:NAME", or a scene dict
    *,
    camera: Union[str, int] = ...,
    eye: Sequence[float] = ...,
    look_at: Sequence[float] = ...,
    up: Sequence[float] = ...,
    fov: float = ...,
    light_samples: int = ...,  # --light-samples
    volumetric: bool = ...,  # --renderer volumetric: objects with their cells baked
    smooth_normals: bool = ...,  # --smooth-normals
    **params: Union[int, float, str],
) -> Scene:
    """'builtin:NAME' with parameters as keywords, a scene .json or a mesh path, or a dict
    holding what a scene .json holds (relative mesh paths: from the current directory); the
    view keywords are the CLI's --camera, --eye, --look-at, --up, --fov. An unknown keyword
    is TypeError, a bad value ValueError."""

def save_image(path: _StrPath, image: Union[RenderResult, npt.ArrayLike]) -> None:
    """Writes H x W x 3 linear RGB as `render --out` does, by extension: .png, .exr, .pfm."""

def to_srgb(image: Union[RenderResult, npt.ArrayLike]) -> npt.NDArray[np.uint8]:
    """Linear RGB as the 8-bit sRGB a PNG output stores (clamped, sRGB curve, rounded)."""

def compare(
    a: Union[RenderResult, npt.ArrayLike], b: Union[RenderResult, npt.ArrayLike]
) -> dict[str, float]:
    """width, height, rmse, psnr_db, ssim, mean_abs_error, max_abs_error, rel_mse (b the
    reference; the names of `amalgam compare --json`)."""

def experiment(
    name: str, quick: bool = True, threads: int = 0, frame: bool = False
) -> Union[list[dict[str, float]], Any]:
    """One of the paper's analyses; its table as a list of rows, or with frame=True as a
    pandas.DataFrame (columns in the CSV's order)."""

def experiment_names() -> list[str]: ...
