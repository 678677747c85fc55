"""
boxplus._core: C++ core of boxplus (manifolds, problem, solver).
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
__all__: list[str] = ['BoxplusError', 'BoxplusIndexError', 'CertifyResult', 'Determinedness', 'EdgeVerdict', 'Factor', 'IterationInfo', 'LoadReport', 'Loss', 'Manifold', 'NoiseModel', 'OutlierReport', 'ParseError', 'PoseGraph', 'Problem', 'ReadReport', 'ResidualCache', 'Rn', 'S2', 'SE2', 'SE3', 'SO2', 'SO3', 'SolveSummary', 'SolverOptions', 'UndeterminedVariable', 'board_factor', 'cached_factor', 'camera_model_names', 'camera_model_size', 'coordinate_prior_factor', 'dh_marker_factor', 'disparity_factor', 'exact_value', 'format_progress', 'format_summary', 'g2o_record_tags', 'gravity_factor', 'gravity_model_size', 'joint_factor', 'landmark_2d_factor', 'loss_names', 'make_manifold', 'make_product_manifold', 'make_python_manifold', 'marker_factor', 'point_factor', 'point_projection_factor', 'pose_graph_implausible_chi2_per_dof', 'pose_graph_solver_defaults', 'prior_factor', 'progress_header', 'relative_pose_factor', 'solver_option_names', 'spline_accel_factor', 'spline_evaluate', 'spline_gyro_factor', 'spline_offset_accel_factor', 'spline_offset_gyro_factor', 'spline_reprojection_factor']
class BoxplusError(ValueError):
    """
    Bad input refused by boxplus.
    """
class BoxplusIndexError(IndexError):
    """
    An id that names no variable or measurement.
    """
class ParseError(BoxplusError):
    """
    A malformed input file; .file and .line name the place.
    """
class NoiseModel:
    """
    Gaussian measurement noise: the whitening W with WᵀW = Ω = Σ⁻¹.
    
    A measurement's residual is r = W e for its error e = f(Y) ⊟ z, so that r
    has unit covariance. Build one with a class method, or let every ``add_*``
    build it from its ``sigma=``, ``covariance=`` or ``information=`` keyword
    (:func:`boxplus.noise.noise_model`). A model of dimension d also whitens an
    error of k·d entries, block by block (all corners of a board).
    """
    class Form:
        """
        Members:
        
          unit
        
          sigmas
        
          covariance
        
          information
        
          sqrt_information
        """
        __members__: typing.ClassVar[dict[str, NoiseModel.Form]]
        covariance: typing.ClassVar[NoiseModel.Form]
        information: typing.ClassVar[NoiseModel.Form]
        sigmas: typing.ClassVar[NoiseModel.Form]
        sqrt_information: typing.ClassVar[NoiseModel.Form]
        unit: typing.ClassVar[NoiseModel.Form]
        @typing.overload
        def __eq__(self, other: NoiseModel.Form) -> bool:
            ...
        @typing.overload
        def __eq__(self, other: typing.Any) -> bool:
            ...
        def __getstate__(self) -> int:
            ...
        def __hash__(self) -> int:
            ...
        def __index__(self) -> int:
            ...
        def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
            ...
        def __int__(self) -> int:
            ...
        @typing.overload
        def __ne__(self, other: NoiseModel.Form) -> bool:
            ...
        @typing.overload
        def __ne__(self, other: typing.Any) -> bool:
            ...
        def __repr__(self) -> str:
            ...
        def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
            ...
        def __str__(self) -> str:
            ...
        @property
        def name(self) -> str:
            ...
        @property
        def value(self) -> int:
            ...
    @staticmethod
    def covariance(covariance: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], what: str = 'noise') -> NoiseModel:
        """
        From Σ (SPD): W = L⁻¹ with LLᵀ = Σ.
        """
    @staticmethod
    def information(information: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], what: str = 'noise') -> NoiseModel:
        """
        From Ω = Σ⁻¹ (SPD): W = U with UᵀU = Ω.
        """
    @staticmethod
    def isotropic(dim: typing.SupportsInt | typing.SupportsIndex, sigma: typing.SupportsFloat | typing.SupportsIndex, what: str = 'noise') -> NoiseModel:
        """
        σ the same in every direction.
        """
    @staticmethod
    def sigmas(sigmas: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], what: str = 'noise') -> NoiseModel:
        """
        Independent errors with standard deviations σᵢ: W = diag(1/σᵢ).
        """
    @staticmethod
    def sqrt_information(sqrt_information: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], what: str = 'noise') -> NoiseModel:
        """
        From W itself (invertible).
        """
    @staticmethod
    def unit(dim: typing.SupportsInt | typing.SupportsIndex) -> NoiseModel:
        """
        W = I (σ = 1).
        """
    def __getstate__(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"], NoiseModel.Form]:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    def unwhiten(self, r: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        e = W⁻¹ r (block by block).
        """
    def whiten(self, e: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        r = W e (block by block).
        """
    @property
    def covariance_matrix(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Σ = W⁻¹W⁻ᵀ.
        """
    @property
    def dim(self) -> int:
        ...
    @property
    def form(self) -> NoiseModel.Form:
        ...
    @property
    def information_matrix(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Ω = WᵀW.
        """
    @property
    def is_unit(self) -> bool:
        ...
    @property
    def sigmas_vector(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        √diag(Σ).
        """
    @property
    def sqrt_information_matrix(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        W (dim × dim).
        """
class Loss:
    """
    A robust loss ρ applied to ‖r‖² of one measurement.
    """
    def __init__(self, name: str, width: typing.SupportsFloat | typing.SupportsIndex = 1.0) -> None:
        """
        name: huber, cauchy, soft_l1, arctan, tukey or none (see loss_names()); width: where it departs from least squares (in whitened units, i.e. standard deviations).
        """
    def __repr__(self) -> str:
        ...
class SolverOptions:
    """
    Settings of a solve (boxplus/solver_options.h), shared by every problem.
    
    Construct with keywords, e.g. ``SolverOptions(method="gn_ls", max_iterations=50)``.
    
    Attributes
    ----------
    method : {'lm', 'gn', 'gn_ls', 'dogleg'}
        Levenberg–Marquardt, Gauss–Newton (trust region, undamped), Gauss–Newton
        with a backtracking line search along x ⊞ αδ (boxplus' own; the
        trust-region fields do not apply), or Powell's dogleg.
    max_iterations, function_tolerance, gradient_tolerance, parameter_tolerance, num_threads
        Ceres' stopping rules and threads.
    initial_trust_region_radius : float
        μ₀ (LM solves (JᵀJ + D/μ) δ = −Jᵀr); 1e16 starts like Gauss–Newton.
    damping : {'marquardt', 'levenberg'}
        D = diag(JᵀJ) (Ceres' default) or D = I (λI, as g2o's LM).
    jacobi_scaling : bool
        Scale the columns of J by 1/(1 + ‖J_k‖) before solving.
    use_nonmonotonic_steps, max_consecutive_nonmonotonic_steps
        Accept up to that many consecutive cost increases while the best cost
        still decreases.
    verbose : bool
        C++ prints one line per iteration (progress_header/format_progress) to stderr.
    """
    __hash__: typing.ClassVar[None] = None
    damping: typing.Any
    function_tolerance: typing.Any
    gradient_tolerance: typing.Any
    initial_trust_region_radius: typing.Any
    jacobi_scaling: typing.Any
    max_consecutive_nonmonotonic_steps: typing.Any
    max_iterations: typing.Any
    method: typing.Any
    num_threads: typing.Any
    parameter_tolerance: typing.Any
    use_nonmonotonic_steps: typing.Any
    verbose: typing.Any
    def __copy__(self) -> SolverOptions:
        ...
    def __deepcopy__(self, memo: dict) -> SolverOptions:
        ...
    def __eq__(self, arg0: typing.Any) -> bool:
        ...
    def __getstate__(self) -> dict:
        ...
    def __init__(self, **kwargs) -> None:
        """
        Keyword construction; unnamed fields keep their defaults. Fields: method, max_iterations, function_tolerance, gradient_tolerance, parameter_tolerance, num_threads, initial_trust_region_radius, damping, jacobi_scaling, use_nonmonotonic_steps, max_consecutive_nonmonotonic_steps, verbose
        """
    def __ne__(self, arg0: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: dict) -> None:
        ...
    def todict(self) -> dict:
        """
        The fields as a dict (keyword arguments of the constructor).
        """
    @property
    def given(self) -> list[str]:
        """
        The fields set by keyword or assignment: a pose graph's solve takes these and its own defaults for the others (boxplus.slam.SOLVER_DEFAULTS).
        """
class IterationInfo:
    """
    What the per-iteration callback receives (read-only).
    
    ``cost`` is Ceres' ½ Σ ρ(‖rᵢ‖²); ``chi2`` = 2·cost is what the progress lines
    print. ``trust_region_radius`` is 0 for the line search, whose step length α
    is ``step_length`` (1 for trust-region methods).
    """
    __hash__: typing.ClassVar[None] = None
    def __copy__(self) -> IterationInfo:
        ...
    def __deepcopy__(self, memo: dict) -> IterationInfo:
        ...
    def __eq__(self, arg0: typing.Any) -> bool:
        ...
    def __getstate__(self) -> dict:
        ...
    def __init__(self, **kwargs) -> None:
        """
        Keyword construction; unnamed fields keep their defaults. Fields: iteration, cost, chi2, cost_change, gradient_max_norm, step_norm, trust_region_radius, step_length, iteration_time_s, cumulative_time_s, step_is_successful
        """
    def __ne__(self, arg0: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: dict) -> None:
        ...
    def todict(self) -> dict:
        """
        The fields as a dict (keyword arguments of the constructor).
        """
    @property
    def chi2(self) -> typing.Any:
        ...
    @property
    def cost(self) -> typing.Any:
        ...
    @property
    def cost_change(self) -> typing.Any:
        ...
    @property
    def cumulative_time_s(self) -> typing.Any:
        ...
    @property
    def gradient_max_norm(self) -> typing.Any:
        ...
    @property
    def iteration(self) -> typing.Any:
        ...
    @property
    def iteration_time_s(self) -> typing.Any:
        ...
    @property
    def step_is_successful(self) -> typing.Any:
        ...
    @property
    def step_length(self) -> typing.Any:
        ...
    @property
    def step_norm(self) -> typing.Any:
        ...
    @property
    def trust_region_radius(self) -> typing.Any:
        ...
class SolveSummary:
    """
    What a solve did and why it stopped (read-only).
    
    ``termination`` is 'convergence', 'no_convergence', 'interrupted' (callback or
    Ctrl-C: the estimate is the last accepted one) or 'failure'; ``usable`` says
    whether the estimate may be used. ``initial_chi2``/``final_chi2`` = 2 × cost.
    """
    __hash__: typing.ClassVar[None] = None
    def __copy__(self) -> SolveSummary:
        ...
    def __deepcopy__(self, memo: dict) -> SolveSummary:
        ...
    def __eq__(self, arg0: typing.Any) -> bool:
        ...
    def __getstate__(self) -> dict:
        ...
    def __init__(self, **kwargs) -> None:
        """
        Keyword construction; unnamed fields keep their defaults. Fields: initial_cost, final_cost, initial_chi2, final_chi2, iterations, time_s, termination, message, usable, report
        """
    def __ne__(self, arg0: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: dict) -> None:
        ...
    def __str__(self) -> str:
        ...
    def todict(self) -> dict:
        """
        The fields as a dict (keyword arguments of the constructor).
        """
    @property
    def final_chi2(self) -> typing.Any:
        ...
    @property
    def final_cost(self) -> typing.Any:
        ...
    @property
    def initial_chi2(self) -> typing.Any:
        ...
    @property
    def initial_cost(self) -> typing.Any:
        ...
    @property
    def iterations(self) -> typing.Any:
        ...
    @property
    def message(self) -> typing.Any:
        ...
    @property
    def report(self) -> typing.Any:
        ...
    @property
    def termination(self) -> typing.Any:
        ...
    @property
    def time_s(self) -> typing.Any:
        ...
    @property
    def usable(self) -> typing.Any:
        ...
class Manifold:
    """
    A manifold as the solver sees it: ambient (storage) coordinates and ⊞/⊟.
    
    Jacobians are those Ceres defines: ``plus_jacobian(x)`` is d(x ⊞ δ)/dδ at
    δ = 0 (ambient × tangent), ``minus_jacobian(x)`` is d(y ⊟ x)/dy at y = x
    (tangent × ambient).
    """
    def __repr__(self) -> str:
        ...
    def minus(self, y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        y ⊟ x in ambient coordinates.
        """
    def minus_batch(self, Y: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], X: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Row-wise y ⊟ x over (N, ambient) arrays.
        """
    def minus_jacobian(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    def plus(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], delta: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        x ⊞ δ in ambient coordinates.
        """
    def plus_batch(self, X: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], D: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Row-wise x ⊞ δ over (N, ambient) and (N, tangent).
        """
    def plus_jacobian(self, x: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def ambient_size(self) -> int:
        ...
    @property
    def kind(self) -> str:
        ...
    @property
    def tangent_size(self) -> int:
        ...
class SO2:
    """
    Planar rotation by an angle φ (radians), kept in [-π, π).
    
    Construct with SO2(phi) or SO2(R) (2×2 rotation matrix).
    
    x + δ = wrap(φ + δ);  y - x = wrap(φ_y − φ_x)  (1 DOF).
    """
    dof: typing.ClassVar[int] = 1
    @staticmethod
    def __matmul__(*args, **kwargs):
        """
        __mul__(*args, **kwargs)
        Overloaded function.
        
        1. __mul__(self: boxplus._core.SO2, arg0: boxplus._core.SO2) -> boxplus._core.SO2
        
        2. __mul__(self: boxplus._core.SO2, arg0: object) -> numpy.typing.NDArray[numpy.float64]
        """
    @staticmethod
    def from_ambient(a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> SO2:
        ...
    @staticmethod
    def from_matrix(R: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 2]"]) -> SO2:
        ...
    @staticmethod
    def manifold() -> Manifold:
        """
        The manifold (⊞/⊟ for the solver) of this kind.
        """
    def __add__(self, delta: typing.Any) -> SO2:
        ...
    def __array__(self, dtype: typing.Any = None, copy: typing.Any = None) -> typing.Any:
        """
        The ambient vector as a new float array (numpy.asarray(x)).
        """
    def __copy__(self) -> SO2:
        ...
    def __deepcopy__(self, memo: dict) -> SO2:
        ...
    def __eq__(self, other: typing.Any) -> typing.Any:
        ...
    def __getstate__(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        ...
    def __hash__(self) -> int:
        ...
    @typing.overload
    def __init__(self, phi: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> None:
        ...
    @typing.overload
    def __init__(self, R: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 2]"]) -> None:
        ...
    def __len__(self) -> int:
        ...
    @typing.overload
    def __mul__(self, arg0: SO2) -> SO2:
        ...
    @typing.overload
    def __mul__(self, arg0: typing.Any) -> numpy.typing.NDArray[numpy.float64]:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    @typing.overload
    def __sub__(self, x: SO2) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @typing.overload
    def __sub__(self, arg0: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    def copy(self) -> SO2:
        ...
    def inverse(self) -> SO2:
        ...
    def isclose(self, other: typing.Any, atol: typing.SupportsFloat | typing.SupportsIndex = 1e-09) -> bool:
        """
        Whether every coordinate of ``self ⊟ other`` is at most ``atol`` in magnitude.
        
        Parameters
        ----------
        other : same type as self
        atol : float
            Tolerance in the tangent's units (radians for rotations, the position's
            units for translations).
        
        Returns
        -------
        bool
        """
    @property
    def R(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 2]"]:
        """
        2×2 rotation matrix.
        """
    @property
    def ambient(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Copy of the storage vector (the layout the solver uses).
        """
    @property
    def phi(self) -> float:
        """
        The angle in radians.
        """
class SO3:
    """
    3D rotation, stored as a unit quaternion [x, y, z, w].
    
    x + δ = x·exp(δ) (δ ∈ R³, body frame);  y - x = log(x⁻¹y), ‖y - x‖ ≤ π.
    Construct with SO3() (identity), SO3(R) (R a 3×3 rotation matrix, a quaternion
    [x, y, z, w] or an SO3), SO3.from_quat([x, y, z, w]) or SO3.exp(rotation_vector).
    """
    dof: typing.ClassVar[int] = 3
    @staticmethod
    def __matmul__(*args, **kwargs):
        """
        __mul__(*args, **kwargs)
        Overloaded function.
        
        1. __mul__(self: boxplus._core.SO3, arg0: boxplus._core.SO3) -> boxplus._core.SO3
        
        2. __mul__(self: boxplus._core.SO3, arg0: object) -> numpy.typing.NDArray[numpy.float64]
        """
    @staticmethod
    def exp(w: typing.Any) -> SO3:
        """
        Rotation by ‖w‖ about w/‖w‖.
        """
    @staticmethod
    def from_ambient(a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> SO3:
        ...
    @staticmethod
    def from_matrix(R: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 3]"]) -> SO3:
        ...
    @staticmethod
    def from_quat(q: typing.Any) -> SO3:
        """
        From a quaternion [x, y, z, w] (normalised).
        """
    @staticmethod
    def from_scipy(rotation: typing.Any) -> SO3:
        """
        SO3 from a single ``scipy.spatial.transform.Rotation``.
        """
    @staticmethod
    def manifold() -> Manifold:
        """
        The manifold (⊞/⊟ for the solver) of this kind.
        """
    def __add__(self, delta: typing.Any) -> SO3:
        ...
    def __array__(self, dtype: typing.Any = None, copy: typing.Any = None) -> typing.Any:
        """
        The ambient vector as a new float array (numpy.asarray(x)).
        """
    def __copy__(self) -> SO3:
        ...
    def __deepcopy__(self, memo: dict) -> SO3:
        ...
    def __eq__(self, other: typing.Any) -> typing.Any:
        ...
    def __getstate__(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        ...
    def __hash__(self) -> int:
        ...
    @typing.overload
    def __init__(self) -> None:
        ...
    @typing.overload
    def __init__(self, R: typing.Any) -> None:
        ...
    def __len__(self) -> int:
        ...
    @typing.overload
    def __mul__(self, arg0: SO3) -> SO3:
        ...
    @typing.overload
    def __mul__(self, arg0: typing.Any) -> numpy.typing.NDArray[numpy.float64]:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    @typing.overload
    def __sub__(self, x: SO3) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @typing.overload
    def __sub__(self, arg0: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    def as_scipy(self) -> typing.Any:
        """
        This rotation as a ``scipy.spatial.transform.Rotation``.
        """
    def copy(self) -> SO3:
        ...
    def inverse(self) -> SO3:
        ...
    def isclose(self, other: typing.Any, atol: typing.SupportsFloat | typing.SupportsIndex = 1e-09) -> bool:
        """
        Whether every coordinate of ``self ⊟ other`` is at most ``atol`` in magnitude.
        
        Parameters
        ----------
        other : same type as self
        atol : float
            Tolerance in the tangent's units (radians for rotations, the position's
            units for translations).
        
        Returns
        -------
        bool
        """
    def log(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        Rotation vector, ‖log‖ ≤ π.
        """
    @property
    def Q(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        """
        3×3 rotation matrix (MTKM's name).
        """
    @property
    def R(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        """
        3×3 rotation matrix.
        """
    @property
    def ambient(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Copy of the storage vector (the layout the solver uses).
        """
    @property
    def quat(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 1]"]:
        """
        Unit quaternion [x, y, z, w].
        """
class SE2:
    """
    Planar pose (position p, angle φ) = R² × SO(2), mapping local to parent.
    
    Tangent order [δx, δy, δφ]: x + δ = (p + δp, wrap(φ + δφ)). Construct with
    SE2() (identity), SE2(x, y, theta), SE2([x, y, theta]) (the ambient vector),
    SE2(T) (3×3 homogeneous matrix), SE2(pos, phi) or SE2(pos, rot) (rot an SO2).
    """
    dof: typing.ClassVar[int] = 3
    @staticmethod
    def __matmul__(*args, **kwargs):
        """
        __mul__(*args, **kwargs)
        Overloaded function.
        
        1. __mul__(self: boxplus._core.SE2, arg0: boxplus._core.SE2) -> boxplus._core.SE2
        
        2. __mul__(self: boxplus._core.SE2, arg0: object) -> numpy.typing.NDArray[numpy.float64]
        """
    @staticmethod
    def exp(delta: typing.Any) -> SE2:
        """
        identity ⊞ [x, y, φ].
        """
    @staticmethod
    def from_ambient(a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> SE2:
        ...
    @staticmethod
    def from_matrix(T: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 3]"]) -> SE2:
        ...
    @staticmethod
    def manifold() -> Manifold:
        """
        The manifold (⊞/⊟ for the solver) of this kind.
        """
    def __add__(self, delta: typing.Any) -> SE2:
        ...
    def __array__(self, dtype: typing.Any = None, copy: typing.Any = None) -> typing.Any:
        """
        The ambient vector as a new float array (numpy.asarray(x)).
        """
    def __copy__(self) -> SE2:
        ...
    def __deepcopy__(self, memo: dict) -> SE2:
        ...
    def __eq__(self, other: typing.Any) -> typing.Any:
        ...
    def __getstate__(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        ...
    def __hash__(self) -> int:
        ...
    @typing.overload
    def __init__(self) -> None:
        ...
    @typing.overload
    def __init__(self, x: typing.SupportsFloat | typing.SupportsIndex, y: typing.SupportsFloat | typing.SupportsIndex, theta: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, v: typing.Any) -> None:
        ...
    @typing.overload
    def __init__(self, pos: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], phi: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @typing.overload
    def __init__(self, pos: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], rot: SO2) -> None:
        ...
    def __len__(self) -> int:
        ...
    @typing.overload
    def __mul__(self, arg0: SE2) -> SE2:
        ...
    @typing.overload
    def __mul__(self, arg0: typing.Any) -> numpy.typing.NDArray[numpy.float64]:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    @typing.overload
    def __sub__(self, x: SE2) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @typing.overload
    def __sub__(self, arg0: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    def copy(self) -> SE2:
        ...
    def fromlocal(self, v: typing.Any) -> numpy.typing.NDArray[numpy.float64]:
        """
        R v + p: local → parent coordinates.
        """
    def inverse(self) -> SE2:
        ...
    def isclose(self, other: typing.Any, atol: typing.SupportsFloat | typing.SupportsIndex = 1e-09) -> bool:
        """
        Whether every coordinate of ``self ⊟ other`` is at most ``atol`` in magnitude.
        
        Parameters
        ----------
        other : same type as self
        atol : float
            Tolerance in the tangent's units (radians for rotations, the position's
            units for translations).
        
        Returns
        -------
        bool
        """
    def log(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        x ⊟ identity.
        """
    def tolocal(self, v: typing.Any) -> numpy.typing.NDArray[numpy.float64]:
        """
        Rᵀ(v − p): parent → local coordinates.
        """
    def transform(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        """
        3×3 homogeneous matrix, local → parent.
        """
    @property
    def R(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 2]"]:
        ...
    @property
    def ambient(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Copy of the storage vector (the layout the solver uses).
        """
    @property
    def phi(self) -> float:
        ...
    @property
    def pos(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    @property
    def rot(self) -> SO2:
        ...
class SE3:
    """
    Rigid transform (rotation R, position p) = R³ × SO(3), mapping local to parent.
    
    Tangent order [δp (3), δθ (3)]: x + δ = (p + δp, R·exp(δθ)). Construct with
    SE3() (identity), SE3(R, t) or SE3(R=..., t=...) (R a 3×3 rotation matrix, a
    quaternion [x, y, z, w] or an SO3; either may be left out: identity rotation,
    zero translation), SE3(T) (4×4 homogeneous matrix), SE3([px, py, pz, qx, qy, qz,
    qw]) (the ambient vector) or SE3.from_matrix(T).
    """
    dof: typing.ClassVar[int] = 6
    @staticmethod
    def __matmul__(*args, **kwargs):
        """
        __mul__(*args, **kwargs)
        Overloaded function.
        
        1. __mul__(self: boxplus._core.SE3, arg0: boxplus._core.SE3) -> boxplus._core.SE3
        
        2. __mul__(self: boxplus._core.SE3, arg0: object) -> numpy.typing.NDArray[numpy.float64]
        """
    @staticmethod
    def exp(delta: typing.Any) -> SE3:
        """
        identity ⊞ [p, w] = (p, exp(w)) (the compound's chart).
        """
    @staticmethod
    def from_ambient(a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> SE3:
        ...
    @staticmethod
    def from_matrix(T: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"]) -> SE3:
        ...
    @staticmethod
    def manifold() -> Manifold:
        """
        The manifold (⊞/⊟ for the solver) of this kind.
        """
    def __add__(self, delta: typing.Any) -> SE3:
        ...
    def __array__(self, dtype: typing.Any = None, copy: typing.Any = None) -> typing.Any:
        """
        The ambient vector as a new float array (numpy.asarray(x)).
        """
    def __copy__(self) -> SE3:
        ...
    def __deepcopy__(self, memo: dict) -> SE3:
        ...
    def __eq__(self, other: typing.Any) -> typing.Any:
        ...
    def __getstate__(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        ...
    def __hash__(self) -> int:
        ...
    @typing.overload
    def __init__(self) -> None:
        ...
    @typing.overload
    def __init__(self, R: typing.Any = None, t: typing.Any = None) -> None:
        ...
    def __len__(self) -> int:
        ...
    @typing.overload
    def __mul__(self, arg0: SE3) -> SE3:
        ...
    @typing.overload
    def __mul__(self, arg0: typing.Any) -> numpy.typing.NDArray[numpy.float64]:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    @typing.overload
    def __sub__(self, x: SE3) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @typing.overload
    def __sub__(self, arg0: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    def copy(self) -> SE3:
        ...
    def fromlocal(self, v: typing.Any) -> numpy.typing.NDArray[numpy.float64]:
        """
        R v + p: local → parent coordinates.
        """
    def inverse(self) -> SE3:
        ...
    def isclose(self, other: typing.Any, atol: typing.SupportsFloat | typing.SupportsIndex = 1e-09) -> bool:
        """
        Whether every coordinate of ``self ⊟ other`` is at most ``atol`` in magnitude.
        
        Parameters
        ----------
        other : same type as self
        atol : float
            Tolerance in the tangent's units (radians for rotations, the position's
            units for translations).
        
        Returns
        -------
        bool
        """
    def log(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        x ⊟ identity = [p, log R].
        """
    def matrix(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        Same as transform().
        """
    def tolocal(self, v: typing.Any) -> numpy.typing.NDArray[numpy.float64]:
        """
        Rᵀ(v − p): parent → local coordinates.
        """
    def transform(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        4×4 homogeneous matrix, local → parent.
        """
    @property
    def Q(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        ...
    @property
    def R(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        ...
    @property
    def ambient(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Copy of the storage vector (the layout the solver uses).
        """
    @property
    def pos(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        Position (translation) p.
        """
    @property
    def quat(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 1]"]:
        ...
    @property
    def rot(self) -> SO3:
        """
        Orientation as an SO3.
        """
    @property
    def t(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        Same as pos.
        """
class S2:
    """
    Unit 3-vector (a direction), 2 DOF.
    
    x + δ = cos‖δ‖ x + sinc‖δ‖ B δ, with B = tangent_basis() (3×2, orthonormal,
    orthogonal to x); y - x ∈ R², ‖y - x‖ = angle between x and y.
    """
    dof: typing.ClassVar[int] = 2
    @staticmethod
    def from_ambient(a: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> S2:
        ...
    @staticmethod
    def manifold() -> Manifold:
        """
        The manifold (⊞/⊟ for the solver) of this kind.
        """
    def __add__(self, delta: typing.Any) -> S2:
        ...
    def __array__(self, dtype: typing.Any = None, copy: typing.Any = None) -> typing.Any:
        """
        The ambient vector as a new float array (numpy.asarray(x)).
        """
    def __copy__(self) -> S2:
        ...
    def __deepcopy__(self, memo: dict) -> S2:
        ...
    def __eq__(self, other: typing.Any) -> typing.Any:
        ...
    def __getstate__(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        ...
    def __hash__(self) -> int:
        ...
    @typing.overload
    def __init__(self) -> None:
        ...
    @typing.overload
    def __init__(self, v: typing.Any) -> None:
        ...
    def __len__(self) -> int:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    @typing.overload
    def __sub__(self, x: S2) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @typing.overload
    def __sub__(self, arg0: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    def copy(self) -> S2:
        ...
    def isclose(self, other: typing.Any, atol: typing.SupportsFloat | typing.SupportsIndex = 1e-09) -> bool:
        """
        Whether every coordinate of ``self ⊟ other`` is at most ``atol`` in magnitude.
        
        Parameters
        ----------
        other : same type as self
        atol : float
            Tolerance in the tangent's units (radians for rotations, the position's
            units for translations).
        
        Returns
        -------
        bool
        """
    def tangent_basis(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 2]"]:
        ...
    @property
    def ambient(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Copy of the storage vector (the layout the solver uses).
        """
    @property
    def vec(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        The unit vector.
        """
class Rn:
    """
    A vector of Rⁿ: Rn(n) is the zero vector, Rn(v) holds v. x + δ = x + δ.
    """
    def __add__(self, arg0: typing.Any) -> Rn:
        ...
    def __array__(self, dtype: typing.Any = None, copy: typing.Any = None) -> typing.Any:
        """
        The ambient vector as a new float array (numpy.asarray(x)).
        """
    def __copy__(self) -> Rn:
        ...
    def __deepcopy__(self, memo: dict) -> Rn:
        ...
    def __eq__(self, other: typing.Any) -> typing.Any:
        ...
    def __getstate__(self) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]]:
        ...
    def __hash__(self) -> int:
        ...
    def __init__(self, v: typing.Any) -> None:
        ...
    def __len__(self) -> int:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: tuple) -> None:
        ...
    @typing.overload
    def __sub__(self, arg0: Rn) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @typing.overload
    def __sub__(self, arg0: typing.Any) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    def copy(self) -> Rn:
        ...
    def isclose(self, other: typing.Any, atol: typing.SupportsFloat | typing.SupportsIndex = 1e-09) -> bool:
        """
        Whether every coordinate of ``self ⊟ other`` is at most ``atol`` in magnitude.
        
        Parameters
        ----------
        other : same type as self
        atol : float
            Tolerance in the tangent's units (radians for rotations, the position's
            units for translations).
        
        Returns
        -------
        bool
        """
    def manifold(self) -> Manifold:
        ...
    @property
    def ambient(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def dof(self) -> int:
        ...
    @property
    def vec(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class UndeterminedVariable:
    """
    The tangent directions of one variable the data leave free.
    """
    def __repr__(self) -> str:
        ...
    def todict(self) -> typing.Any:
        """
        The properties as a dict of plain Python values (json.dumps takes it).
        """
    @property
    def directions(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Orthonormal columns in the variable's tangent coordinates.
        """
    @property
    def moves_with(self) -> list[int]:
        """
        The variables these directions are tied to (a shared null vector).
        """
    @property
    def variable(self) -> int:
        ...
class Determinedness:
    """
    The rank test of a problem's Jacobian at its current values.
    
    Columns are equilibrated (J D⁻¹), and a direction counts as undetermined when
    its singular value is below ``tolerance`` times the largest; see
    ``boxplus/determinedness.h`` for the method.
    """
    def __repr__(self) -> str:
        ...
    def todict(self) -> typing.Any:
        """
        The properties as a dict of plain Python values (json.dumps takes it).
        """
    @property
    def column_norms(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def column_offsets(self) -> list[int]:
        ...
    @property
    def determined(self) -> bool:
        ...
    @property
    def largest_singular_value(self) -> float:
        ...
    @property
    def null_space(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Orthonormal basis of the null space in equilibrated coordinates.
        """
    @property
    def nullity(self) -> int:
        ...
    @property
    def num_columns(self) -> int:
        ...
    @property
    def rank(self) -> int:
        ...
    @property
    def tolerance(self) -> float:
        ...
    @property
    def undetermined(self) -> list[UndeterminedVariable]:
        ...
    @property
    def variables(self) -> list[int]:
        ...
class Problem:
    """
    The C++ least-squares problem: variables on manifolds and whitened residuals.
    The public, friendlier front is boxplus.OptimizationProblem.
    """
    def __init__(self) -> None:
        ...
    def __repr__(self) -> str:
        ...
    def add_factor(self, factor: Factor, loss: Loss | None = None, name: str = '') -> int:
        """
        Adds a factor; returns its measurement id. The problem keeps its NoiseModel, so error() and errors() are in the measurement's own units.
        """
    def add_residual_cache(self, cache: ResidualCache) -> None:
        """
        Registers a group so that it is evaluated before each solver step.
        """
    def add_variable(self, manifold: Manifold, init: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], name: str = '') -> int:
        ...
    def check_determined(self, relative_tolerance: typing.SupportsFloat | typing.SupportsIndex = 1e-09, support_tolerance: typing.SupportsFloat | typing.SupportsIndex = 1e-06) -> Determinedness:
        """
        The rank test of the Jacobian at the current values (kept until the problem or its values change): which tangent directions the measurements leave free.
        """
    def cost(self) -> float:
        """
        ½ Σ ρ(‖rᵢ‖²) at the current values.
        """
    def covariance(self, id: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Marginal covariance in the variable's tangent space.
        """
    def describe_undetermined(self, determinedness: Determinedness) -> str:
        """
        "'b': x, y (tied to 'a'); ...": the undetermined variables and their free directions, named with the variables' direction labels.
        """
    def error(self, measurement_id: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Un-whitened error e = W⁻¹ r of one measurement, in its own units.
        """
    def errors(self, measurement_ids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], whitened: bool = False) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Errors e = W⁻¹ r (or, whitened, the residuals r) of several measurements, concatenated in the order given, the measurements evaluated once.
        """
    def evaluate_jacobian(self) -> dict:
        """
        Whitened residuals and their dense Jacobian in the tangent spaces of the free variables: a dict with residuals (m,), jacobian (m, n), variables (free ids), column_offsets, row_offsets (per measurement).
        """
    def is_fixed(self, id: typing.SupportsInt | typing.SupportsIndex) -> bool:
        ...
    def joint_covariance(self, ids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    def measurement_name(self, id: typing.SupportsInt | typing.SupportsIndex) -> str:
        ...
    def measurement_variables(self, id: typing.SupportsInt | typing.SupportsIndex) -> list[int]:
        ...
    def noise(self, measurement_id: typing.SupportsInt | typing.SupportsIndex) -> NoiseModel:
        """
        The noise model a measurement whitens with.
        """
    def normal_matrix(self) -> dict:
        """
        JᵀJ of the whitened Jacobian (dense n × n, formed from the sparse J) in the tangent spaces of the free variables: a dict with normal_matrix, residuals (whitened, as evaluate_jacobian's), variables (free ids) and column_offsets.
        """
    def residual(self, measurement_id: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Whitened residual of one measurement.
        """
    def restore_value(self, id: typing.SupportsInt | typing.SupportsIndex, value: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        """
        set_value for a value read with value(id): the same bits back (for copies).
        """
    def set_direction_labels(self, id: typing.SupportsInt | typing.SupportsIndex, labels: collections.abc.Sequence[str]) -> None:
        """
        Names of the variable's tangent directions, used when a message names an undetermined direction.
        """
    def set_fixed(self, id: typing.SupportsInt | typing.SupportsIndex, fixed: bool = True) -> None:
        ...
    def set_value(self, id: typing.SupportsInt | typing.SupportsIndex, value: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> None:
        ...
    def solve(self, options: typing.Any = None, callback: typing.Any = None, **kwargs) -> SolveSummary:
        """
        Minimises ½ Σ ρ(‖rᵢ‖²) with ⊞ steps.
        
        Parameters
        ----------
        options : SolverOptions, optional
            The settings (default: SolverOptions()).
        callback : callable, optional
            ``callback(info: IterationInfo)`` after each iteration; return False to
            stop (None or True continue). Ctrl-C stops the solve and keeps the last
            accepted estimate (termination 'interrupted').
        **overrides
            Fields of SolverOptions that replace those of ``options``
            (``nonmonotonic_steps=n`` sets both nonmonotonic fields).
        
        Returns
        -------
        SolveSummary
            Raises the Python exception of a failing measurement function, manifold
            or callback, with its traceback.
        """
    def value(self, id: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        Copy of the variable's ambient vector.
        """
    def values(self, ids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex]) -> numpy.typing.NDArray[numpy.float64]:
        """
        Ambient values of several same-sized variables, one per row (a copy).
        """
    def variable_name(self, id: typing.SupportsInt | typing.SupportsIndex) -> str:
        ...
    @property
    def generation(self) -> int:
        """
        Changes whenever values, fixed flags, variables or measurements change (a cache key for results of the current state).
        """
    @property
    def num_measurements(self) -> int:
        ...
    @property
    def num_variables(self) -> int:
        ...
class Factor:
    """
    A measurement built by one of the factor functions of ``boxplus._core``
    (whitened residual r = W e, its variables, its NoiseModel), ready for
    ``Problem.add_factor``. Not picklable: a problem is copied by replaying the
    public calls that built it (:mod:`boxplus._journal`).
    """
    def __repr__(self) -> str:
        ...
    @property
    def noise(self) -> NoiseModel:
        ...
    @property
    def residual_size(self) -> int:
        ...
    @property
    def variables(self) -> list[int]:
        ...
class ResidualCache:
    """
    A group of measurements evaluated together by a Python callable
    ``prepare(jacobians: bool, new_point: bool) -> (E, Js)`` with the errors E of
    shape (N, m), not whitened, and, when jacobians is True, Js a list of
    (N, m, tangent_size_k) arrays (their Jacobians). Each measurement's
    NoiseModel whitens them in C++ (``cached_factor``).
    """
    def __init__(self, prepare: typing.Any, residual_size: typing.SupportsInt | typing.SupportsIndex, tangent_sizes: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], name: str = '') -> None:
        ...
class ReadReport:
    """
    What the g2o reader counted.
    """
    def todict(self) -> typing.Any:
        """
        The properties as a dict of plain Python values (json.dumps takes it).
        """
    @property
    def lines(self) -> int:
        ...
    @property
    def repaired_information(self) -> int:
        ...
    @property
    def repaired_lines(self) -> list[int]:
        ...
    @property
    def unknown_skipped(self) -> int:
        ...
    @property
    def unknown_tags(self) -> dict[str, int]:
        """
        Skipped tag → count (bytes outside ASCII escaped as \\xNN).
        """
class LoadReport:
    """
    What loading a pose graph did (boxplus::slam::LoadReport): the reader's counts
    (``unknown_skipped``, ``unknown_tags``, ``repaired_information``,
    ``repaired_lines``, ``lines``), its ``warnings`` ("" if none),
    ``estimates_from_file`` (False: no VERTEX lines, initialised by spanning tree),
    ``start`` (the start the solve begins from: "file", "spanning-tree" or
    "chordal"; what init="best" chose) and the seconds of the three steps (``read_s``, ``init_s``, ``build_s``).
    """
    def __repr__(self) -> str:
        ...
    def todict(self) -> typing.Any:
        """
        The properties as a dict of plain Python values (json.dumps takes it).
        """
    @property
    def build_s(self) -> float:
        ...
    @property
    def estimates_from_file(self) -> bool:
        ...
    @property
    def init_s(self) -> float:
        ...
    @property
    def lines(self) -> int:
        ...
    @property
    def read_s(self) -> float:
        ...
    @property
    def repaired_information(self) -> int:
        ...
    @property
    def repaired_lines(self) -> list[int]:
        ...
    @property
    def start(self) -> str:
        ...
    @property
    def unknown_skipped(self) -> int:
        ...
    @property
    def unknown_tags(self) -> dict[str, int]:
        ...
    @property
    def warnings(self) -> str:
        ...
class EdgeVerdict:
    """
    An edge judged a wrong loop closure (boxplus::slam::EdgeVerdict).
    """
    def __repr__(self) -> str:
        ...
    def todict(self) -> typing.Any:
        """
        The properties as a dict of plain Python values (json.dumps takes it).
        """
    @property
    def chi2(self) -> float:
        """
        eᵀΩe at the returned estimate.
        """
    @property
    def edge(self) -> int:
        """
        Index among the graph's edges.
        """
    @property
    def from_id(self) -> int:
        ...
    @property
    def line(self) -> int:
        """
        Line of the file (0: added in code).
        """
    @property
    def to_id(self) -> int:
        ...
    @property
    def weight(self) -> float:
        """
        GNC's last weight (0).
        """
class OutlierReport:
    """
    What the last solve decided about wrong loop closures
    (boxplus::slam::OutlierReport; docs/guide/slam.md "Wrong loop closures"):
    ``ran`` (GNC ran), ``method`` ('gnc-tls' / 'gnc-gm'), ``threshold`` (c̄² of
    a 2D/3D pose edge, times ``information_scale``: eᵀΩe above it is an
    outlier), ``information_scale`` (1, or the inliers' χ²/dof when it showed
    the file's information under-confident and GNC judged again in those
    units), ``candidates`` (loop closures judged), ``rounds``, ``outliers``
    (EdgeVerdict list, file order).
    """
    def __repr__(self) -> str:
        ...
    def todict(self) -> typing.Any:
        """
        The properties as a dict of plain Python values (json.dumps takes it).
        """
    @property
    def candidates(self) -> int:
        ...
    @property
    def information_scale(self) -> float:
        ...
    @property
    def method(self) -> str:
        ...
    @property
    def outliers(self) -> list[EdgeVerdict]:
        ...
    @property
    def ran(self) -> bool:
        ...
    @property
    def rounds(self) -> int:
        ...
    @property
    def threshold(self) -> float:
        ...
class PoseGraph:
    """
    A pose graph read from a g2o/TORO file, as a boxplus Problem
    (boxplus::slam::PoseGraph; boxplus.slam.PoseGraph extends it).
    
    ``PoseGraph(path, ...)`` reads, initialises and builds it in C++
    (boxplus::slam::LoadPoseGraph, the command line's path too); ``problem`` is the
    underlying ``boxplus.Problem`` (extend it, fix variables, solve it), its
    lifetime tied to this object; ``report`` the LoadReport.
    """
    def __init__(self, path: str, convention: str = 'g2o', robust: str = 'none', robust_width: typing.SupportsFloat | typing.SupportsIndex = 1.0, init: str = 'best', skip_unknown: bool = False, repair_information: bool = False, progress: typing.Any = None) -> None:
        """
        Reads a file and builds the problem (raises boxplus.ParseError naming file:line); progress(lines, bytes_read, bytes_total), if given, is called every 4096 lines of the read.
        """
    def __repr__(self) -> str:
        ...
    def add_edge(self, kind: str, from_id: typing.SupportsInt | typing.SupportsIndex, to_id: typing.SupportsInt | typing.SupportsIndex, measurement: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], information: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"]) -> int:
        """
        Adds an edge to the graph (saved with it) and the problem; returns the
        measurement id. kind: 'SE2', 'SE3' (measurement [t, qx, qy, qz, qw]), 'SE2_XY',
        'SE3_XYZ', 'SE2_BEARING_RANGE' ([bearing, range]). information: the full
        symmetric information matrix in the error's order. The call is checked
        completely first: one that raises leaves the graph unchanged.
        """
    def add_vertex(self, vertex_id: typing.SupportsInt | typing.SupportsIndex, kind: str, estimate: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> int:
        """
        Adds a vertex ('SE2', 'SE3', 'XY', 'XYZ'); returns its variable id. The call is checked completely first: one that raises leaves the graph unchanged.
        """
    def certify(self, tolerance: typing.SupportsFloat | typing.SupportsIndex = 1e-06, max_rank: typing.SupportsInt | typing.SupportsIndex = 10) -> CertifyResult:
        """
        Proves the current solution globally optimal, or not (SE-Sync's certificate:
        one sparse Cholesky factorisation; Rosen et al., IJRR 2019). In the 'sesync'
        convention a solution that is not certified is improved by the Riemannian
        staircase up to rank ``max_rank`` (the graph's dimension: verify only) and
        solved again in place. In other conventions the certificate of SE-Sync's
        objective is evaluated at the solution as it is. Returns a CertifyResult.
        Raises boxplus.BoxplusError for graphs it does not cover (landmarks, priors,
        offsets, a robust kernel, more than one fixed vertex, several components).
        
        Parameters
        ----------
        tolerance : float
            Certify when f − f* ≤ tolerance·f is proven.
        max_rank : int
            Highest rank of the Riemannian staircase.
        """
    def chi2(self, convention: str = '') -> float:
        """
        Σ eᵀΩe over the graph's edges at the current values ('g2o', 'log', 'compound' or 'sesync'; default: the graph's convention).
        """
    def chi2_per_dof(self) -> float:
        """
        χ² / (residuals − free tangent dimensions) at the current values: ≈ 1 for a graph whose information matrices fit its errors; NaN without degrees of freedom.
        """
    def edge_chi2(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        eᵀΩe of every edge at the current values (file order, the graph's convention): which measurements carry the error.
        """
    def edge_vertices(self) -> numpy.typing.NDArray[numpy.int64]:
        """
        (from, to) vertex ids of every edge of the file, file order; to = -1 for a file's unary edge (a prior record).
        """
    def fix(self, vertex_id: typing.SupportsInt | typing.SupportsIndex, fixed: bool = True) -> None:
        ...
    def landmarks(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Current landmark positions, one row per point vertex (file order).
        """
    def poses(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Current pose estimates, one ambient row per pose vertex (file order).
        """
    def save(self, path: str) -> None:
        """
        Writes the graph with the current values (file's ids, order and tags).
        """
    def solve(self, options: typing.Any = None, callback: typing.Any = None, **kwargs) -> SolveSummary:
        """
        Solves in place (boxplus::slam::PoseGraph::Solve: when restart_when_implausible is on and the solution is implausible (see chi2_per_dof), judges the loop closures by GNC and returns the inliers' optimum (outlier_mode 'auto'; outlier_report says which), or with outlier_mode 'off' also solves from the file's estimate and from a Huber-kernel solution, keeping the lowest chi2); the arguments of Problem.solve.
        """
    def to_string(self) -> str:
        """
        The file that save() would write.
        """
    def variable(self, vertex_id: typing.SupportsInt | typing.SupportsIndex) -> int:
        """
        Variable id (in ``problem``) of a vertex id.
        """
    def vertex_kind(self, vertex_id: typing.SupportsInt | typing.SupportsIndex) -> str:
        ...
    def write_back(self) -> None:
        ...
    @property
    def convention(self) -> str:
        ...
    @property
    def dimension(self) -> int:
        ...
    @property
    def gauge_vertex(self) -> int:
        ...
    @property
    def has_second_start(self) -> bool:
        """
        Whether the next solve may also start from the file's estimate.
        """
    @property
    def inlier_probability(self) -> float:
        """
        GNC's inlier threshold: the quantile of χ²(d) at this probability (0.99).
        """
    @inlier_probability.setter
    def inlier_probability(self, arg1: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def num_edges(self) -> int:
        ...
    @property
    def outlier_mode(self) -> str:
        """
        What solve() does about wrong loop closures: 'auto' (GNC-TLS when the least-squares solution is implausible), 'gnc-tls' or 'gnc-gm' (always), 'off' (never: the lowest least-squares minimum).
        """
    @outlier_mode.setter
    def outlier_mode(self, arg1: str) -> None:
        ...
    @property
    def outlier_report(self) -> OutlierReport:
        """
        The OutlierReport of the last solve.
        """
    @property
    def problem(self) -> Problem:
        """
        The boxplus.Problem (owned by this graph).
        """
    @property
    def report(self) -> LoadReport:
        """
        The LoadReport of the file.
        """
    @property
    def restart_when_implausible(self) -> bool:
        """
        Whether the next solve, if its solution is implausible (chi2_per_dof > IMPLAUSIBLE_CHI2_PER_DOF), also solves from other starts and keeps the lowest chi2: on after load_g2o(..., init='best').
        """
    @restart_when_implausible.setter
    def restart_when_implausible(self, arg1: bool) -> None:
        ...
    @property
    def vertex_ids(self) -> list[int]:
        ...
class CertifyResult:
    """
    What PoseGraph.certify proved (SE-Sync's certificate, docs/guide/certify.md).
    ``certified``: the solution is the global optimum of SE-Sync's
    objective f up to the tolerance (f − f* ≤ tolerance·f proven);
    ``lower_bound``: a proven lower bound on the global optimum f* (−inf if none);
    ``suboptimality_bound``: f − lower_bound; ``lambda_min``: the certificate's
    smallest eigenvalue when the test failed (NaN when it passed: then it is
    > −eta); ``max_rank_reached``: the staircase's highest rank (the graph's
    dimension when none was needed); times in seconds.
    """
    def __repr__(self) -> str:
        ...
    def todict(self) -> typing.Any:
        """
        The properties as a dict of plain Python values (json.dumps takes it).
        """
    @property
    def certified(self) -> bool:
        ...
    @property
    def eta(self) -> float:
        ...
    @property
    def interrupted(self) -> bool:
        ...
    @property
    def lambda_min(self) -> float:
        ...
    @property
    def lower_bound(self) -> float:
        ...
    @property
    def max_rank_reached(self) -> int:
        ...
    @property
    def message(self) -> str:
        ...
    @property
    def objective(self) -> float:
        ...
    @property
    def solution_changed(self) -> bool:
        ...
    @property
    def solve_time_s(self) -> float:
        ...
    @property
    def staircase_used(self) -> bool:
        ...
    @property
    def stationarity(self) -> float:
        ...
    @property
    def suboptimality_bound(self) -> float:
        ...
    @property
    def verify_time_s(self) -> float:
        ...
def _native_log_drain() -> list:
    """
    The queued glog messages of Ceres as (severity, file, line, message); severity 0 INFO, 1 WARNING, 2 ERROR, 3 FATAL. Used by boxplus.log.
    """
def _native_log_dropped() -> int:
    """
    How many glog messages the full queue has dropped.
    """
def _native_log_emit(severity: typing.SupportsInt | typing.SupportsIndex, message: str) -> None:
    """
    Logs one glog message from C++, as Ceres does (for the tests of the routing).
    """
def board_factor(model: str, intrinsics: typing.SupportsInt | typing.SupportsIndex, world_from_rig: typing.SupportsInt | typing.SupportsIndex, cam_from_rig: typing.SupportsInt | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 2]"], noise: NoiseModel, p_in_world: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"]) -> Factor:
    """
    All points of a board in one residual block: z (N, 2) pixels, p_in_world (N, 3), noise of one corner (2-dim); see factors/camera/board.h.
    """
def cached_factor(problem: Problem, cache: ResidualCache, ids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], noise: NoiseModel, what: str = 'measurement') -> Factor:
    """
    The next measurement of a ResidualCache group, on variables ids, whitened by noise.
    """
def camera_model_names() -> list[str]:
    """
    The camera models every camera term takes (camera/models.h), in C++'s order.
    """
def camera_model_size(model: str) -> int:
    """
    Number of intrinsic parameters of a camera model.
    """
def coordinate_prior_factor(problem: Problem, id: typing.SupportsInt | typing.SupportsIndex, indices: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], noise: NoiseModel, what: str = 'prior') -> Factor:
    """
    r = W (x[indices] − z) on some coordinates of the Rn variable id; the others are left to the data; see factors/pose/prior.h.
    """
def dh_marker_factor(model: str, intrinsics: typing.SupportsInt | typing.SupportsIndex, base_from_rig: typing.SupportsInt | typing.SupportsIndex, p_in_hand: typing.SupportsInt | typing.SupportsIndex, cam_from_rig: typing.SupportsInt | typing.SupportsIndex, dh: typing.SupportsInt | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], noise: NoiseModel, joints: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], base_from_chain: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[7, 1]"], flange_from_hand: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[7, 1]"]) -> Factor:
    """
    Marker on a hand through a DH chain with unknown parameters dh (n×4: θ offset, d, a, α) from joint readings; see factors/kinematics/marker.h.
    """
def disparity_factor(world_from_rig: typing.SupportsInt | typing.SupportsIndex, cam_from_rig: typing.SupportsInt | typing.SupportsIndex, disparity_params: typing.SupportsInt | typing.SupportsIndex, d: typing.SupportsFloat | typing.SupportsIndex, noise: NoiseModel, p_in_world: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> Factor:
    """
    Kinect-style disparity d = a / Z + b of a board point, noise 1-dim; see factors/depth/disparity.h.
    """
def exact_value(kind: str, ambient: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> typing.Any:
    """
    The SO3, SE3 or S2 value with exactly these ambient numbers (from_ambient normalises again, which can move the last bit); for copies of a problem.
    """
def format_progress(info: IterationInfo) -> str:
    """
    One progress line (χ², change, |gradient|, |step|, radius/α, time) for an iteration.
    """
def format_summary(summary: SolveSummary) -> str:
    """
    The closing line of a solve: termination, χ² before → after, time.
    """
def g2o_record_tags() -> list:
    """
    The record tags the g2o/TORO reader accepts, as (tag, format, fields) from the reader's one tag table (boxplus::io::RecordTags).
    """
def gravity_factor(model: str, world_from_rig: typing.SupportsInt | typing.SupportsIndex, imu_from_rig: typing.SupportsInt | typing.SupportsIndex, accel: typing.SupportsInt | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], noise: NoiseModel, g_in_world: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], imu_size: typing.SupportsInt | typing.SupportsIndex = 7) -> Factor:
    """
    Gravity in the IMU: r = W (T R(imu_from_rig) R(world_from_rig)ᵀ g_in_world + b − z); accel ignored for model 'rotation'; imu_size 4 (SO3 imu_from_rig) or 7 (SE3); see factors/imu/gravity.h.
    """
def gravity_model_size(model: str) -> int:
    """
    Size of the accelerometer block of a gravity model (rotation 0, scale 1, scale_bias 4, axis_scale_bias 6, axis_scale_bias_misalignment 9).
    """
def joint_factor(problem: Problem, spec: dict, noise: NoiseModel, what: str = 'joint term') -> Factor:
    """
    One term of joint calibration (link, distance, plane, line, line_anchor, projection, target_projection) over 3D-system points (constant, variable, DH chain, light sheet, beam); see factors/joint/terms.h. Variables are given by id inside the nested dict ``spec``.
    """
def landmark_2d_factor(world_from_pose: typing.SupportsInt | typing.SupportsIndex, p_in_world: typing.SupportsInt | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], noise: NoiseModel, what: str = 'point') -> Factor:
    """
    A 2-D landmark (Rn(2) variable) seen from an SE2 pose: r = W (x⁻¹ · l − z); 2-dim noise; see factors/pose/observed_point.h.
    """
def loss_names() -> list[str]:
    """
    The accepted loss names.
    """
def make_manifold(kind: str, n: typing.SupportsInt | typing.SupportsIndex = 0) -> Manifold:
    """
    The manifold of a built-in kind: 'Rn' (with n), 'SO2', 'SO3', 'SE2', 'SE3', 'S2'.
    """
def make_product_manifold(members: collections.abc.Sequence[Manifold]) -> Manifold:
    """
    The Cartesian product of the given manifolds; ⊞/⊟ act member-wise.
    """
def make_python_manifold(ambient_size: typing.SupportsInt | typing.SupportsIndex, tangent_size: typing.SupportsInt | typing.SupportsIndex, plus: typing.Any, minus: typing.Any, name: str = 'Python') -> Manifold:
    """
    A manifold whose ⊞ (plus(x, δ)) and ⊟ (minus(y, x)) are Python functions on ambient vectors.
    """
def marker_factor(model: str, intrinsics: typing.SupportsInt | typing.SupportsIndex, base_from_rig: typing.SupportsInt | typing.SupportsIndex, p_in_hand: typing.SupportsInt | typing.SupportsIndex, cam_from_rig: typing.SupportsInt | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], noise: NoiseModel, base_from_hand: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[7, 1]"]) -> Factor:
    """
    Marker on a hand, base_from_hand from forward kinematics (constant); see factors/kinematics/marker.h.
    """
def point_factor(world_from_rig: typing.SupportsInt | typing.SupportsIndex, cam_from_rig: typing.SupportsInt | typing.SupportsIndex, p_in_world_id: typing.SupportsInt | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], noise: NoiseModel, p_in_world: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], what: str = 'point') -> Factor:
    """
    3-D point in the camera: r = W (cam_from_rig ∘ world_from_rig⁻¹ ∘ p_in_world − z); p_in_world_id < 0 uses the constant p_in_world; 3-dim noise; see factors/pose/observed_point.h.
    """
def point_projection_factor(model: str, intrinsics: typing.SupportsInt | typing.SupportsIndex, world_from_rig: typing.SupportsInt | typing.SupportsIndex, cam_from_rig: typing.SupportsInt | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], noise: NoiseModel, p_in_world: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> Factor:
    """
    Projection r = W (π(k, cam_from_rig · world_from_rig⁻¹ · p_in_world) − z); see factors/camera/point_projection.h.
    """
def pose_graph_solver_defaults() -> dict:
    """
    The solver settings boxplus uses for pose graphs (boxplus::slam::DefaultSolverOptions), as keyword arguments of Problem.solve.
    """
def prior_factor(problem: Problem, id: typing.SupportsInt | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], noise: NoiseModel, what: str = 'prior') -> Factor:
    """
    r = W (x ⊟ z) on variable id of the problem (any built-in manifold); z in ambient coordinates; see factors/pose/prior.h.
    """
def progress_header() -> str:
    """
    The column titles of format_progress lines.
    """
def relative_pose_factor(world_from_a: typing.SupportsInt | typing.SupportsIndex, world_from_b: typing.SupportsInt | typing.SupportsIndex, a_from_b: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], noise: NoiseModel, what: str = 'relative pose') -> Factor:
    """
    r = W ((world_from_a⁻¹ ∘ world_from_b) ⊟ a_from_b) on SE2 (3-dim noise) or SE3 (6-dim), tangent [δp, δθ]; see factors/pose/relative_pose.h.
    """
def solver_option_names() -> list[str]:
    """
    The settable fields of SolverOptions.
    """
def spline_accel_factor(knots: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], bias: typing.SupportsInt | typing.SupportsIndex, gravity: typing.SupportsInt | typing.SupportsIndex, u: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], noise: NoiseModel, g: typing.SupportsFloat | typing.SupportsIndex = 9.81, intrinsics: typing.SupportsInt | typing.SupportsIndex | None = None, size_effect: typing.SupportsInt | typing.SupportsIndex | None = None) -> Factor:
    """
    r = W (M R(t)ᵀ (a(t) − g ĝ) + b_a − z); gravity: an S2 variable ĝ (the direction of gravity in the world frame), M as spline_gyro_factor's; size_effect: an Rn(6) [r_y, r_z] of the y and z sensing elements; see factors/imu/spline_terms.h.
    """
def spline_evaluate(knots: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 7]"], u: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
    """
    (p, q, v, a, ω_body, α_body) of the R³ × SO(3) cubic B-spline segment whose 4 control points are the rows [p, q] of knots, at u (see factors/imu/se3_spline.h).
    """
def spline_gyro_factor(knots: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], bias: typing.SupportsInt | typing.SupportsIndex, u: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], noise: NoiseModel, intrinsics: typing.SupportsInt | typing.SupportsIndex | None = None) -> Factor:
    """
    r = W (M ω_imu(t) + b_g − z), M the scale and misalignment of the Rn(6) variable intrinsics (identity without); see factors/imu/spline_terms.h.
    """
def spline_offset_accel_factor(knots: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], body_from_imu: typing.SupportsInt | typing.SupportsIndex, bias: typing.SupportsInt | typing.SupportsIndex, gravity: typing.SupportsInt | typing.SupportsIndex, u: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], noise: NoiseModel, g: typing.SupportsFloat | typing.SupportsIndex = 9.81, time_offset: typing.SupportsInt | typing.SupportsIndex | None = None, d0: typing.SupportsFloat | typing.SupportsIndex = 0.0, intrinsics: typing.SupportsInt | typing.SupportsIndex | None = None) -> Factor:
    """
    Another IMU's accelerometer, with its lever arm: r = W (M R_kᵀ (R(t)ᵀ (a − g ĝ) + α × r + ω × (ω × r)) + b_a − z), M as spline_offset_gyro_factor's; see factors/imu/spline_terms.h.
    """
def spline_offset_gyro_factor(knots: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], body_from_imu: typing.SupportsInt | typing.SupportsIndex, bias: typing.SupportsInt | typing.SupportsIndex, u: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], noise: NoiseModel, time_offset: typing.SupportsInt | typing.SupportsIndex | None = None, d0: typing.SupportsFloat | typing.SupportsIndex = 0.0, intrinsics: typing.SupportsInt | typing.SupportsIndex | None = None) -> Factor:
    """
    Another IMU's gyroscope: r = W (M R_kᵀ ω + b_g − z), with time_offset (an Rn(1) id) read at body time t + d, u computed with d = d0; M the scale and misalignment of the Rn(6) variable intrinsics (identity without); see factors/imu/spline_terms.h.
    """
def spline_reprojection_factor(model: str, knots: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], imu_from_cam: typing.SupportsInt | typing.SupportsIndex, offset: typing.SupportsInt | typing.SupportsIndex, intrinsics: typing.SupportsInt | typing.SupportsIndex, t_rel: typing.SupportsFloat | typing.SupportsIndex, dt: typing.SupportsFloat | typing.SupportsIndex, z: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"], noise: NoiseModel, p_in_world: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], line_delay: typing.SupportsInt | typing.SupportsIndex | None = None) -> Factor:
    """
    A target corner seen at camera time t_c = t_i + t_rel: r = W (π(k, cam_from_world(t_c + d) p) − z); with line_delay (an R¹ variable ℓ, s per row) a rolling shutter: the pose at t_c + d + ℓ z_v. See factors/imu/spline_terms.h.
    """
__version__: str = '0.1.0'
pose_graph_implausible_chi2_per_dof: float = 10.0
