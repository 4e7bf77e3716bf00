"""deformbench from Python: handle-based mesh deformation methods, measures and verdicts.

Arrays follow libigl's Python bindings: ``V`` is ``#V x 3`` float64 positions, ``F`` is ``#F x 3``
integer faces (counter-clockwise seen from outside), vertex lists are 1-D integer arrays. Lists and
other array-likes are converted as ``numpy.asarray`` does. A bad array raises ``ValueError`` naming
the argument and its first bad element (``V[12, 1] is nan (not finite)``); a method, measure or
configuration error raises ``DeformbenchError`` with the command line's message.

Methods and their parameters come from ``configs/methods.toml`` of the current directory when it
has one (a deformbench checkout), else from the copy built into the module: the same as
``harness run`` from the same directory, so results agree with it to the last bit.
"""

from os import PathLike
from typing import Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
Number = Union[bool, int, float, str, list, dict]

class DeformbenchError(Exception):
    """A method, measure or configuration error (the command line's message)."""

class Method:
    """A deformation method precomputed on a rest mesh, in the papers' phases.

    ``Method(name, V, F, **params)`` precomputes (libigl's ``*_precomputation``), ``bind`` takes
    the handle set, ``solve`` the handles' targets (libigl's ``*_solve``). Re-``bind`` for another
    handle set; ``solve`` again for other targets (an edit step goes on from the last result).

    Inputs:
        name: a method of ``methods()``: ``hirm``, ``isolines``, ``spectral_mhb``,
            ``scale_aware``, ``laplacian``, ``arap``, or a variant (``scale_aware_ora``, ...).
        V: ``#V x 3`` rest positions.
        F: ``#F x 3`` faces, indices into ``V``.
        **params: parameters laid over the configuration's (README, "Methods and parameters";
            ``configs/methods.toml`` documents each), e.g. ``tolerance=1e-6``.

    Attributes (of the last call):
        name, iterations, converged, precompute_seconds, bind_seconds, solve_seconds.

    Raises:
        ValueError: a bad array. DeformbenchError: an unknown method or parameter, a mesh the
        method cannot precompute on.
    """

    name: str
    iterations: int
    converged: bool
    precompute_seconds: float
    bind_seconds: float
    solve_seconds: float

    def __init__(self, name: str, V: ArrayLike, F: ArrayLike, **params: Number) -> None: ...
    def bind(self, fixed: ArrayLike, handles: Optional[Sequence[ArrayLike]] = None) -> None:
        """Bind the handle set.

        Inputs:
            fixed: ``#f`` vertices held at their rest positions (may be empty).
            handles: ``#H`` lists of vertices, each a region moved as a unit by ``solve``.
                No vertex in two regions.
        """
    def solve(self, targets: Optional[Sequence[ArrayLike]] = None) -> npt.NDArray[np.float64]:
        """Deform.

        Inputs:
            targets: ``#H`` arrays, ``targets[i]`` the ``#h_i x 3`` positions of the vertices of
                ``handles[i]`` in their order.
        Outputs:
            ``#V x 3`` deformed positions.
        """
    def positions(self) -> npt.NDArray[np.float64]:
        """``#V x 3`` current positions (the rest mesh before the first solve)."""
    def statistics(self) -> list[tuple[str, float]]:
        """The method's own figures of its last solve, by name (e.g. ``arap``'s saddle test)."""

class Scenario:
    """A scenario file loaded as the harness loads it (``load_scenario``).

    Attributes:
        name, mesh_source (``survey``, ``procedural look-alike`` or ``file``), V (``#V x 3``),
        F (``#F x 3``), n_steps.
    """

    name: str
    mesh_source: str
    V: npt.NDArray[np.float64]
    F: npt.NDArray[np.int64]
    n_steps: int

    def fixed(self, step: int = 0) -> list[int]:
        """The vertices held at edit step ``step``: ``Method.bind``'s ``fixed``."""
    def handles(self, step: int = 0) -> list[list[int]]:
        """The handle regions of step ``step``: ``Method.bind``'s ``handles``."""
    def targets(self, step: int = 0, current: Optional[ArrayLike] = None) -> list[npt.NDArray[np.float64]]:
        """Where the handles of step ``step`` go from ``current`` (``#V x 3``, default the rest
        mesh): ``Method.solve``'s ``targets``."""

def methods() -> list[str]:
    """The names ``Method`` takes: built-in methods and the configuration's variants."""

def load_scenario(path: Union[str, PathLike], survey_dir: Optional[Union[str, PathLike]] = None) -> Scenario:
    """Load a single-mesh scenario: a file (``configs/scenarios/bar.toml`` or a user's), or the
    name of one of the configuration's (``"bar"``), on the survey
    data of ``survey_dir`` (default: ``$DEFORM_SURVEY_DIR``), else on its procedural look-alike."""

def measures(
    V0: ArrayLike,
    F: ArrayLike,
    V1: ArrayLike,
    fixed: Optional[ArrayLike] = None,
    handles: Optional[Sequence[ArrayLike]] = None,
    targets: Optional[Sequence[ArrayLike]] = None,
    reference: Optional[ArrayLike] = None,
) -> dict[str, Optional[float]]:
    """Every measure of the metrics table of a result, by column name (README, "Reading the
    results"); ``None`` where one does not apply (the volume of an open mesh, ``*_to_arap``
    without ``reference``).

    Inputs:
        V0: ``#V x 3`` rest positions. F: ``#F x 3`` faces. V1: ``#V x 3`` result.
        fixed: ``#f`` vertices held at rest. handles: ``#H`` vertex lists.
        targets: ``#H`` arrays, ``#h_i x 3`` where ``handles[i]`` was asked to go.
        reference: ``#V x 3`` result of ``arap`` on the same edit, if any.
    """

def verdict(
    V0: ArrayLike,
    F: ArrayLike,
    V1: ArrayLike,
    fixed: Optional[ArrayLike] = None,
    handles: Optional[Sequence[ArrayLike]] = None,
    targets: Optional[Sequence[ArrayLike]] = None,
    reference: Optional[ArrayLike] = None,
) -> dict:
    """``measures`` and the harness's verdict on them (``configs/verdicts.toml``):
    ``{"status": "ok" | "suspect", "reasons": [str, ...], "measures": {...}}``. ``reference``
    (``arap``'s result on the same edit) widens the size verdicts by its own change, as on the page.
    """

def run(
    scenarios: Sequence[str],
    methods: Sequence[Union[str, object, tuple[str, object]]],
    reports: Optional[Union[str, PathLike]] = None,
    survey_dir: Optional[Union[str, PathLike]] = None,
    threads: Optional[int] = None,
    repeat: int = 1,
    mesh_format: str = "glb",
) -> list[dict]:
    """Run ``scenarios`` × ``methods`` through the harness's runner and write its reports
    (``reports``, default ``./reports``: results.csv/json, index.html, figures), as
    ``harness run --scenario ... --method ...``; returns the rows of ``results.json``.

    Inputs:
        scenarios: names of ``configs/scenarios/`` or scenario files.
        methods: method names (``methods()``), and Python methods, judged, timed and reported like
            an external method (``origin = "external"``): an object with the protocol's phases
            ``precompute(V, F)``, ``bind(regions)``, ``solve(constrained, targets)`` (regions and
            ``constrained`` 1-D int arrays, ``targets`` ``#b x 3``; docs/protocol.md), or a class
            of them (one instance per case), or a function ``f(V, F, constrained, targets)``.
            ``solve``/``f`` returns the ``#V x 3`` positions, or a dict with ``positions`` and
            optionally ``iterations`` and ``converged``. Named by their ``name`` or ``__name__``,
            or given as ``(name, object)``.
        survey_dir: the survey data (default ``$DEFORM_SURVEY_DIR``; else procedural look-alikes).
        threads: worker threads of every method (default: every core). Cases run one at a time.
        repeat: repetitions of each case's timed phases.
        mesh_format: result meshes as ``"glb"``, ``"off"`` or ``"both"``.
    Raises:
        DeformbenchError: a scenario or configuration error, a name taken. A Python method that
        raises makes its case ``failed`` with the exception's type and message, not the run.
    """
