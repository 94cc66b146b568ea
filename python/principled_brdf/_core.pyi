"""principled_brdf native core (use the principled_brdf package, not this module).

Stubs for the pybind11 extension (cpp/bindings/*.cpp). The functions take
packed arguments the Python side has already checked: directions as float32
(N, 3), (3, N) or (3,) arrays with a layout code (0 (N, 3), 1 (3, N), 2 one
(3,) vector for every element), ``model`` an index into MODEL_NAMES,
``sampler`` one into SAMPLER_NAMES, ``isa`` "" (the CPU's choice) or one of
``cpu_info()["available"]``. The batch functions take every argument by
keyword, their scalar options as one EvalOptions, PdfOptions or
SampleOptions; they write into the float32 arrays they are given and return
-1, or the index of an element whose direction failed the check.
tests/api/test_stubs_and_mypy.py keeps these in step with the module's own signatures.
"""

from collections.abc import Sequence
from types import ModuleType
from typing import Annotated, Any, Final, SupportsFloat, SupportsIndex, SupportsInt, TypedDict, type_check_only

import numpy as np
from numpy.typing import ArrayLike, NDArray
from typing_extensions import TypeAlias

_Int: TypeAlias = SupportsInt | SupportsIndex
_Float: TypeAlias = SupportsFloat | SupportsIndex
# An input the binding converts to a C-contiguous array of that dtype (a copy if needed).
_Float32In: TypeAlias = Annotated[ArrayLike, np.float32]
_Float64In: TypeAlias = Annotated[ArrayLike, np.float64]
# An output: written in place, so it must already be a C-contiguous array of that dtype.
_Float32Out: TypeAlias = NDArray[np.float32]
# One entry per parameter of PARAMETER_TABLE, in its order: a number (base_color:
# three numbers) when uniform, else a float32 array of N values ((N, 3) for base_color).
_Params: TypeAlias = Sequence[float | Sequence[float] | NDArray[np.float32]]
# (count, length, 14 offset tables or None, 11 flags): a call in segments reading broadcast inputs in place
_Segments: TypeAlias = tuple[int, int, Sequence[NDArray[np.int64] | None], Sequence[bool]]

# (name, first slot, slots, defaults, lower bound, upper bound) per parameter
PARAMETER_TABLE: Final[list[tuple[str, int, int, tuple[float, ...], float, float]]]
PARAM_SLOTS: Final[int]
MODEL_NAMES: Final[tuple[str, ...]]
MODEL_TABLE: Final[tuple[dict[str, Any], ...]]  # one row per model: docs/model.md, "Adding a model"
LOBE_NAMES: Final[tuple[str, ...]]
SAMPLED_LOBE_NAMES: Final[tuple[str, ...]]
SAMPLER_NAMES: Final[tuple[str, ...]]
MODE_NAMES: Final[tuple[str, ...]]
GRADIENT_SLOTS: Final[int]

@type_check_only
class _CpuInfo(TypedDict):
    isa: str
    float_lanes: int
    available: list[str]
    threads: int

def reference_eval(
    wi: _Float64In,
    wo: _Float64In,
    params: _Float64In,
    model: _Int,
    lobes: bool,
    energy_compensation: bool = False,
    mode: _Int = 0,
) -> NDArray[np.float64]:
    """Float64 reference f (N,3) or lobes (N,6,3) for packed, already validated rows."""

def reference_eval_grad(
    wi: _Float64In, wo: _Float64In, params: _Float64In, model: _Int, mode: _Int = 0, energy_compensation: bool = False
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Float64 reference f (N,3) and its Jacobian (N,3,P) over the model's P parameter slots, for packed validated rows."""

def reference_eval_direction_grad(
    wi: _Float64In,
    wo: _Float64In,
    params: _Float64In,
    model: _Int,
    cosine: bool = False,
    mode: _Int = 0,
    energy_compensation: bool = False,
) -> NDArray[np.float64]:
    """Float64 reference derivatives (N,3,6) of f (times |cos θl| if cosine) in wi_x, wi_y, wi_z, wo_x, wo_y, wo_z."""

def reference_sample(
    wo: _Float64In,
    u: _Float64In,
    params: _Float64In,
    model: _Int,
    sampler: _Int,
    energy_compensation: bool = False,
    mode: _Int = 0,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.int32]]:
    """Float64 reference samples (wi (N,3), pdf (N,), weight (N,3), lobe (N,) int32) for validated rows;
    each input is N rows or one shared row."""

def reference_pdf(
    wi: _Float64In, wo: _Float64In, params: _Float64In, model: _Int, sampler: _Int, energy_compensation: bool = False
) -> NDArray[np.float64]:
    """Float64 reference mixture pdf (N,) for validated rows (N or one shared row each)."""

def reference_lobe_probabilities(
    wo: _Float64In, params: _Float64In, model: _Int = 0, energy_compensation: bool = False
) -> NDArray[np.float64]:
    """Lobe probabilities (N,3), (N,4) for the 2015 models, at wo for validated rows (N or one shared row each)."""

class EvalOptions:
    """The options of batch_eval and batch_eval_grad."""

    model: int
    cosine: bool
    energy_compensation: bool
    mode: int
    check_tolerance: float
    threads: int
    isa: str
    def __init__(
        self,
        *,
        model: _Int = 0,
        cosine: bool = False,
        energy_compensation: bool = False,
        mode: _Int = 0,
        check_tolerance: _Float = 0.0,
        threads: _Int = 0,
        isa: str = "",
    ) -> None: ...

class PdfOptions:
    """The options of batch_pdf (model and cosine: of the value, if any)."""

    model: int
    sampler: int
    cosine: bool
    energy_compensation: bool
    mode: int
    check_tolerance: float
    threads: int
    isa: str
    def __init__(
        self,
        *,
        model: _Int = 0,
        sampler: _Int = 0,
        cosine: bool = False,
        energy_compensation: bool = False,
        mode: _Int = 0,
        check_tolerance: _Float = 0.0,
        threads: _Int = 0,
        isa: str = "",
    ) -> None: ...

class SampleOptions:
    """The options of batch_sample."""

    model: int
    sampler: int
    energy_compensation: bool
    mode: int
    seed: int
    check_tolerance: float
    threads: int
    isa: str
    def __init__(
        self,
        *,
        model: _Int = 0,
        sampler: _Int = 0,
        energy_compensation: bool = False,
        mode: _Int = 0,
        seed: _Int = 0,
        check_tolerance: _Float = 0.0,
        threads: _Int = 0,
        isa: str = "",
    ) -> None: ...

def batch_eval(
    *,
    wi: _Float32In,
    wi_layout: _Int,
    wo: _Float32In,
    wo_layout: _Int,
    params: _Params,
    outputs: Sequence[_Float32Out],
    out_layout: _Int,
    n: _Int,
    lobes: bool,
    options: EvalOptions,
    segments: _Segments | None = None,
) -> int:
    """SIMD evaluation (f, or the lobes) into preallocated float32 outputs (validated by the caller); segments: (count, length, offsets, single), inputs read in place per segment."""

def batch_eval_grad(
    *,
    wi: _Float32In,
    wi_layout: _Int,
    wo: _Float32In,
    wo_layout: _Int,
    params: _Params,
    out: _Float32Out,
    jacobian: _Float32Out,
    out_layout: _Int,
    n: _Int,
    options: EvalOptions,
    columns: Sequence[int] | None = None,
    segments: _Segments | None = None,
) -> int:
    """SIMD f and its Jacobian over the parameter slots (columns: their indices, None for all) into preallocated float32 outputs."""

def batch_eval_vjp(
    *,
    wi: _Float32In,
    wi_layout: _Int,
    wo: _Float32In,
    wo_layout: _Int,
    params: _Params,
    cotangent: _Float32In,
    cotangent_layout: _Int,
    vjp: _Float32Out,
    out_layout: _Int,
    n: _Int,
    options: EvalOptions,
    columns: Sequence[int] | None = None,
    segments: _Segments | None = None,
) -> int:
    """SIMD vector-Jacobian product Σ_c g_c ∂f_c/∂p per element into a preallocated float32 output."""

def batch_eval_direction_grad(
    *,
    wi: _Float32In,
    wi_layout: _Int,
    wo: _Float32In,
    wo_layout: _Int,
    params: _Params,
    out: _Float32Out,
    jacobian: _Float32Out,
    out_layout: _Int,
    n: _Int,
    options: EvalOptions,
    segments: _Segments | None = None,
) -> int:
    """SIMD f and its Jacobian in wi_x, wi_y, wi_z, wo_x, wo_y, wo_z into preallocated float32 outputs."""

def batch_eval_direction_vjp(
    *,
    wi: _Float32In,
    wi_layout: _Int,
    wo: _Float32In,
    wo_layout: _Int,
    params: _Params,
    cotangent: _Float32In,
    cotangent_layout: _Int,
    vjp: _Float32Out,
    out_layout: _Int,
    n: _Int,
    options: EvalOptions,
    segments: _Segments | None = None,
) -> int:
    """SIMD Σ_c g_c ∂f_c/∂w per element for the six direction components into a preallocated float32 output."""

def normal_equations(
    *,
    wi: _Float32In,
    wo: _Float32In,
    slots: _Float32In,
    target: _Float32In,
    scale: _Float32In,
    problems: NDArray[np.int64],
    columns: Sequence[int] | None,
    loss: _Int,
    cosine: bool,
    model: _Int,
    threads: _Int = 0,
    isa: str = "",
    gain: _Float32In | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """(normal, gradient, cost) of the residuals (u(gain f) - target) scale of each listed problem, by the SIMD kernels: JᵀJ's upper triangle by rows, Jᵀr and Σ r² (float64)."""

def damped_steps(
    normal: NDArray[np.float64],
    gradient: NDArray[np.float64],
    damping: NDArray[np.float64],
    free: NDArray[np.bool_],
) -> NDArray[np.float64]:
    """Per problem, δ solving (A + diag(damping)) δ = -gradient over the free parameters (0 for the others; NaN where the damped matrix is not positive definite)."""

def batch_pdf(
    *,
    wi: _Float32In,
    wi_layout: _Int,
    wo: _Float32In,
    wo_layout: _Int,
    params: _Params,
    pdf: _Float32Out,
    out: _Float32Out | None = None,
    out_layout: _Int = 0,
    n: _Int,
    options: PdfOptions,
    segments: _Segments | None = None,
) -> int:
    """SIMD sampling pdf into a preallocated float32 array (and f into out, in the same pass, if given)."""

def batch_sample(
    *,
    wo: _Float32In,
    wo_layout: _Int,
    u: _Float32In | None,
    u_layout: _Int,
    params: _Params,
    wi: _Float32Out,
    weight: _Float32Out,
    pdf: _Float32Out,
    lobe: NDArray[np.int32],
    lobe_weights: Sequence[_Float32Out] | None = None,
    out_layout: _Int,
    n: _Int,
    options: SampleOptions,
    segments: _Segments | None = None,
) -> int:
    """SIMD sampling into preallocated outputs (and each lobe's share of the weight, if given)."""

def counter_uniforms(seed: _Int, first: _Int, n: _Int) -> NDArray[np.float32]:
    """The counter-based uniforms (n, 3) that sampling uses for elements first .. first + n - 1."""

def direction_length2_bounds(tolerance: _Float) -> tuple[float, float]:
    """(lowest, highest): a direction passes the check when its float64 squared length lies within."""

def memory_roofline(wi: _Float32In, wo: _Float32In, out: _Float32Out, threads: _Int) -> None:
    """out = wi + wo over (N, 3) float32 arrays: the bytes eval moves, at memory speed."""

def cpu_info() -> _CpuInfo:
    """Instruction set in use, the available ones, SIMD width, hardware threads."""

def float_lanes(isa: str) -> int: ...

# The submodule principled_brdf._core.microfacet (an attribute of _core, not an
# importable module): float64 rows, each argument N rows or one shared row.
@type_check_only
class _MicrofacetModule(ModuleType):
    """Microfacet toolkit (docs/microfacet.md) over packed float64 rows."""

    @staticmethod
    def gtr_d(cos_theta_h: _Float64In, alpha: _Float64In, gamma: _Float64In, closed_forms: bool) -> NDArray[np.float64]: ...
    @staticmethod
    def gtr_pdf(h: _Float64In, alpha: _Float64In, gamma: _Float64In, closed_forms: bool) -> NDArray[np.float64]: ...
    @staticmethod
    def gtr_sample(
        u1: _Float64In, u2: _Float64In, alpha: _Float64In, gamma: _Float64In, closed_forms: bool
    ) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_d(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_pdf(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_lambda(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_g1(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_g2_separable(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_g2_height_correlated(
        wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In
    ) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_pdf_visible(h: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_sample(u1: _Float64In, u2: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_sample_visible(
        wo: _Float64In, u1: _Float64In, u2: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In
    ) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_d(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_pdf(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_lambda(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_g1(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def student_t_d(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def student_t_pdf(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def student_t_lambda(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def student_t_g1(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def student_t_g2_separable(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def student_t_g2_height_correlated(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def student_t_pdf_visible(h: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def student_t_sample(u1: _Float64In, u2: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def exponential_power_d(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def exponential_power_pdf(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def exponential_power_lambda(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def exponential_power_g1(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def exponential_power_g2_separable(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def exponential_power_g2_height_correlated(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def exponential_power_pdf_visible(h: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def exponential_power_sample(u1: _Float64In, u2: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def blinn_phong_d(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def blinn_phong_pdf(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def blinn_phong_lambda(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def blinn_phong_g1(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def blinn_phong_g2_separable(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def blinn_phong_g2_height_correlated(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def blinn_phong_pdf_visible(h: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def blinn_phong_sample(u1: _Float64In, u2: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_walter_d(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_walter_pdf(h: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_walter_lambda(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_walter_g1(w: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_walter_g2_separable(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_walter_g2_height_correlated(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_walter_pdf_visible(h: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, shape: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_g2_separable(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_g2_height_correlated(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_pdf_visible(h: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def ggx_g2_over_4cos(wi: _Float64In, wo: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In, form: int) -> NDArray[np.float64]: ...
    @staticmethod
    def hyp2f1(a: _Float64In, b: _Float64In, c: _Float64In, z: _Float64In) -> NDArray[np.float64]: ...
    def fresnel_dielectric(cos_theta: _Float64In, eta: _Float64In) -> NDArray[np.float64]: ...
    def fresnel_conductor(cos_theta: _Float64In, eta: _Float64In, k: _Float64In) -> NDArray[np.float64]: ...
    def refract(w: _Float64In, eta: _Float64In) -> NDArray[np.float64]: ...
    def generalized_half_vector(wi: _Float64In, wo: _Float64In, eta: _Float64In) -> NDArray[np.float64]: ...
    def refraction_jacobian(wi: _Float64In, wo: _Float64In, eta: _Float64In) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_sample_visible(
        wo: _Float64In, u1: _Float64In, u2: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In
    ) -> NDArray[np.float64]: ...
    @staticmethod
    def beckmann_sample(u1: _Float64In, u2: _Float64In, alpha_x: _Float64In, alpha_y: _Float64In) -> NDArray[np.float64]: ...

microfacet: Final[_MicrofacetModule]
