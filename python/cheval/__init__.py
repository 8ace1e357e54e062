"""cheval: robot trajectory evaluation with Chebyshev methods, from Python.

A thin face over the C++ library, as the ``cheval`` command is (docs/python.md)::

    import cheval
    gt = cheval.read("V102_groundtruth.csv")           # stamps (int64 ns), positions (n, 3), ...
    r = cheval.ape(gt, "V102.txt", align="se3")        # the dict of `cheval ape ... --json`
    v = cheval.velocity(gt, angular=True)              # Chebyshev velocities and body rates

Trajectories and files go in wherever one is expected: a path (str or os.PathLike), a
``cheval.Trajectory``, or a mapping with the Trajectory constructor's keys (``stamps``,
``positions``, optional ``quaternions``, ``velocities``, ``angular_velocities``). Arrays come out
as numpy arrays over the library's memory (no copy) where the layout allows; see docs/python.md for
where a copy is made. Errors are the library's typed errors with its messages, options spelled as
the keyword arguments of these functions:
``InputError`` and ``UsageError`` (both ``ValueError``), ``ComputeError`` (``RuntimeError``),
``OutputError`` (``OSError``), all subclasses of ``cheval.Error``.
"""

import json as _json
import os as _os
from collections.abc import Mapping as _Mapping

from . import _cheval
from ._cheval import (  # noqa: F401  (re-exported)
    ComputeError,
    Compression,
    Curve,
    Error,
    InputError,
    Model,
    OutputError,
    Trajectory,
    UsageError,
    simulate,
)

__all__ = [
    "Error", "InputError", "UsageError", "ComputeError", "OutputError",
    "Trajectory", "Curve", "Model", "Compression",
    "read", "write", "simulate", "velocity", "fit", "compress", "sample", "read_model", "write_model",
    "associate", "align", "ape", "rpe", "ase",
    "DEFAULT_VEHICLE", "simulate_quadrotor", "estimate_quadrotor",
]

#: The FlightGoggles quadrotor and camera (docs/estimator.md), the estimator's default vehicle file.
DEFAULT_VEHICLE = _os.path.join(_os.path.dirname(__file__), "vehicles", "flightgoggles.json")

for _cls in (Trajectory, Curve, Model, Compression):
    _cls.__module__ = "cheval"  # shown as cheval.Trajectory, where users find them

# The library's defaults these signatures show (each lives in its options struct).
_DEFAULTS = _cheval.defaults()
_T_MAX_DIFF, _T_OFFSET = _DEFAULTS["t_max_diff"], _DEFAULTS["t_offset"]


def _path(path, keyword="path"):
    """A path argument (str or os.PathLike) as text; one with a NUL byte, which the C library would cut
    short at the NUL, raises UsageError (a ValueError) naming the keyword."""
    text = _os.fspath(path)
    if isinstance(text, bytes):
        text = _os.fsdecode(text)
    if "\0" in text:
        raise UsageError(f"{keyword}: the file name contains a NUL byte (\\0); expected a path")
    return text


def _columns_text(columns):
    """A column map given as a list of role names, or as the CLI's comma-separated text."""
    if columns is None:
        return ""
    return columns if isinstance(columns, str) else ",".join(columns)


def read(path, format="auto", columns=None, kitti_times=None, topic=None, bag_time=False, quat_order="xyzw"):
    """Reads a trajectory file exactly as the CLI does (docs/formats.md) and returns a Trajectory.

    format: 'auto' (decided from the content), 'tum', 'tumv', 'euroc', 'kitti', 'vins' or 'csv';
    columns: a column map, e.g. 't_ns,px,py,pz,qw,qx,qy,qz' or a list of role names (implies csv;
    '_' skips a column); kitti_times: a file with one stamp (seconds) per KITTI pose.
    topic: for a recording (ROS 1 bag, ROS 2 bag folder, MCAP; docs/bags.md) the topic, or
    '/tf:PARENT.CHILD' for a tf chain; bag_time: stamps from the record time, not the headers.
    quat_order: the order of the returned trajectory's ``quaternions`` array, 'xyzw' (cheval's and
    TUM's) or 'wxyz' (evo's ``orientations_quat_wxyz``); the file's own order is set by its format.
    Raises InputError ('PATH:LINE:COLUMN: error: ...') for bad input, UsageError for bad arguments.
    """
    return _cheval.read(_path(path), format, _columns_text(columns),
                        "" if kitti_times is None else _path(kitti_times, "kitti_times"), topic or "", bool(bag_time),
                        quat_order)


def write(trajectory, path, format="tum"):
    """Writes a trajectory atomically (a temporary file renamed into place) in tum, tumv, euroc or
    kitti, and only what cheval.read reads back. Raises ComputeError when the trajectory lacks what
    the format needs (orientation; velocity for tumv) or holds what no reader accepts (no pose),
    before anything is written, and OutputError when the file cannot be written.
    """
    _cheval.write(trajectory, _path(path), format)


def read_model(path):
    """Reads a model file written by ``cheval.write_model`` or ``cheval compress`` (a Model)."""
    return _cheval.read_model(_path(path))


def write_model(model, path):
    """Writes a model file atomically (OutputError when it cannot)."""
    _cheval.write_model(model, _path(path))


def _trajectory(source, format="auto", columns=None, kitti_times=None, quat_order=None, topic=None,
                bag_time=False):
    """A Trajectory from a path, a Trajectory or a mapping of its constructor's arguments (quaternions in
    quat_order, else the mapping's own 'quat_order', else x y z w; stamps int64 ns or float seconds);
    topic / bag_time for a recording's path (docs/bags.md)."""
    if (topic is not None or bag_time) and not isinstance(source, (str, _os.PathLike)):
        raise TypeError("topic / bag_time apply to a recording's path, not to a " + type(source).__name__)
    if isinstance(source, Trajectory):
        return source
    if isinstance(source, (str, _os.PathLike)):
        return read(source, format, columns, kitti_times, topic, bag_time, quat_order=quat_order or "xyzw")
    if isinstance(source, _Mapping):
        arrays = dict(source)
        if quat_order is not None:
            arrays["quat_order"] = quat_order
        return Trajectory(**arrays)
    raise TypeError(f"expected a path, a cheval.Trajectory or a mapping of arrays, got {type(source).__name__}")


def _stamps(at):
    """Query stamps: an int64 array (ns) or the stamps of a Trajectory."""
    return at.stamps if isinstance(at, Trajectory) else at


def _trajectory_to_dict(self):
    """The trajectory's arrays by the constructor's names (views, no copy); None for absent channels."""
    arrays = {"stamps": self.stamps, "positions": self.positions, "quaternions": self.quaternions,
              "velocities": self.velocities, "angular_velocities": self.angular_velocities}
    if self.quat_order != "xyzw":
        arrays["quat_order"] = self.quat_order  # so that Trajectory(**t.to_dict()) reads them in that order
    return arrays


Trajectory.to_dict = _trajectory_to_dict


def velocity(source, *, at=None, method="chebyshev", degree="auto", window=None, savgol_window=21,
             angular=False, threads=0, format="auto", columns=None, kitti_times=None, quat_order=None):
    """World-frame linear velocity from positions, as ``cheval velocity`` (docs/velocity.md).

    source: a path, Trajectory or mapping (positions are used; orientations with angular=True).
    at: int64 stamps (ns) or a Trajectory whose stamps to evaluate at (default: the source's own).
    method: 'chebyshev' (windowed Chebyshev least squares, differentiated), 'central' or 'savgol'.
    degree: 'auto' (= 'cv'), 'chop' or an int (a fixed degree: one global fit unless
    a window is given); window: the Chebyshev window in seconds (default adaptive);
    savgol_window: the Savitzky-Golay window in samples (odd, >= 5). angular: also body angular
    velocity from the orientations. threads: for the Chebyshev fit (0: every core; the result is
    the same for any number).

    Returns a dict: 'stamps' (n,) int64, 'velocities' (n, 3) m/s, 'positions' (n, 3) fitted
    (chebyshev; else None), 'angular_velocities' (n, 3) rad/s or None, 'orientations' (n, 4) x y z w
    fitted (chebyshev with angular) or None, 'curve' (the fitted Curve, chebyshev) or None,
    'angular_residual_rms' (rad) or None, 'rounded_stamps' ({'resolution_s', 'rate_hz'} where the
    stamps were a uniform rate rounded to a coarser resolution and the fit took the uniform instants,
    docs/velocity.md "Rounded stamps"; else None). No array is copied on the way out.
    quat_order: 'xyzw' or 'wxyz', the order of a mapping's quaternions and of 'orientations' (default:
    the source trajectory's quat_order; 'wxyz' copies 'orientations').
    """
    trajectory = _trajectory(source, format, columns, kitti_times, quat_order)
    out = _cheval.velocity(trajectory, at=None if at is None else _stamps(at), method=method,
                           degree=degree, window=window, savgol_window=savgol_window, angular=angular,
                           threads=threads)
    if trajectory.quat_order == "wxyz" and out.get("orientations") is not None:
        import numpy as _np
        out["orientations"] = _np.roll(out["orientations"], 1, axis=1)
    return out


def fit(source, values=None, *, degree="auto", window=None, noise=None, threads=0, format="auto",
        columns=None, kitti_times=None):
    """A Curve fitted to samples: fit(stamps, values) with int64 stamps (ns) and values (n, d),
    d <= 4, or fit(trajectory_or_path) for its positions. Evaluate it with curve.evaluate(stamps,
    order). degree: 'auto' (= 'cv'), 'chop' or an int; window (s); noise (sigma of the
    samples; default estimated); threads (0: every core; the curve is the same for any number).
    See cheval.Curve.
    """
    if values is not None:
        _cheval.check_real(values, "values")
        return _cheval.fit(source, values, degree=degree, window=window, noise=noise, threads=threads)
    return _cheval.fit(_trajectory(source, format, columns, kitti_times), degree=degree, window=window,
                       noise=noise, threads=threads)


def compress(source, values=None, *, tolerance=None, format="auto", columns=None, kitti_times=None):
    """The pseudo-spectral model of samples, as ``cheval compress`` (docs/compress.md):
    compress(stamps, values) or compress(trajectory_or_path) for its positions. tolerance: the
    largest error accepted at every sample (units of the samples, metres for positions), or
    None for the automatic fit. Returns a Compression (.model, .ratio, .max_error, ...).
    """
    if values is not None:
        _cheval.check_real(values, "values")
        return _cheval.compress(source, values, tolerance=tolerance)
    return _cheval.compress(_trajectory(source, format, columns, kitti_times), tolerance=tolerance)


def sample(model, *, rate=None, at=None):
    """Values of a model (a Model or a model file's path), as ``cheval sample``: every 1/rate s
    from its first stamp to its last (gaps skipped), or at int64 stamps / a Trajectory's stamps
    ``at``. Returns {'stamps': (n,) int64, 'values': (n, d)}.
    """
    if not isinstance(model, Model):
        model = read_model(model)
    return _cheval.sample(model, rate=rate, at=None if at is None else _stamps(at))


def _sides(ref, est, options):
    """The reference and estimate Trajectories, with the CLI's input options: format / columns /
    kitti_times for both, ref_* and est_* for one side."""
    def side(source, prefix):
        def get(name):
            value = options.get(prefix + name)
            return options.get(name) if value is None else value
        return _trajectory(source, get("format") or "auto", get("columns"), get("kitti_times"), get("quat_order"),
                           get("topic"), bool(get("bag_time")))
    return side(ref, "ref_"), side(est, "est_")


_INPUT_OPTIONS = {f"{prefix}{name}" for prefix in ("", "ref_", "est_")
                  for name in ("format", "columns", "kitti_times", "quat_order")}
# Recordings (docs/bags.md): topic / ref_topic / est_topic and bag_time (record time) per side.
_INPUT_OPTIONS |= {f"{prefix}{name}" for prefix in ("", "ref_", "est_") for name in ("topic", "bag_time")}


def _check_input_options(function, options):
    unknown = set(options) - _INPUT_OPTIONS
    if unknown:
        raise TypeError(f"{function}() got unexpected keyword argument(s): {', '.join(sorted(unknown))}")


def associate(ref, est, *, t_max_diff=_T_MAX_DIFF, t_offset=_T_OFFSET, **inputs):
    """evo's time association (docs/evaluation.md): for each pose of the shorter trajectory the
    nearest stamp of the other within t_max_diff seconds (inclusive), est + t_offset = ref.
    Returns {'ref': (k,) int64 indices, 'est': (k,) int64 indices, 'by_index': bool} (KITTI files
    without stamps pair pose i with pose i). Input options as in ape().
    """
    _check_input_options("associate", inputs)
    r, e = _sides(ref, est, inputs)
    return _cheval.associate(r, e, t_max_diff=t_max_diff, t_offset=t_offset)


def align(ref, est, *, method="se3", n_align=0, t_max_diff=_T_MAX_DIFF, t_offset=_T_OFFSET, **inputs):
    """The alignment of the estimate onto the reference from the associated pairs, as ``--align``:
    method 'none', 'origin', 'se3', 'sim3', 'scale', 'posyaw' or 'full'; n_align: solve from the
    first N pairs (0: all). Returns {'method', 'rotation' (3, 3), 'translation' (3,), 'scale',
    'pairs_used', 'trajectory'}; an estimate state maps to R' = R R_i, p' = R (c p_i) + t, v' = c R v_i,
    and 'trajectory' is the whole estimate so mapped (a Trajectory, every pose, in the estimate's
    quat_order; the keys before it are as they were before it was added).
    """
    _check_input_options("align", inputs)
    r, e = _sides(ref, est, inputs)
    return _cheval.align(r, e, method=method, n_align=n_align, t_max_diff=t_max_diff, t_offset=t_offset)


def _evaluate(metric, ref, est, errors, inputs, options):
    _check_input_options(metric, inputs)
    r, e = _sides(ref, est, inputs)
    text, per_pair = _cheval.evaluate(r, e, metric, **options)
    result = _json.loads(text)
    if errors:
        result["errors"] = per_pair
    return result


_COMMON_DOC = """
    ref, est: paths, Trajectories or mappings of arrays. Input options as the CLI's: format,
    columns, kitti_times for both files, ref_format, est_columns, ... for one side.
    Recordings: topic (both sides), ref_topic / est_topic (e.g. '/tf:odom.base_link'), bag_time.
    align: 'none', 'origin', 'se3', 'sim3', 'scale', 'posyaw' or 'full'; n_align: solve it from the
    first N pairs; t_max_diff, t_offset (s): the association (est + t_offset = ref);
    association: 'nearest' (evo) or 'continuous' (the reference's Chebyshev curve at the estimate
    stamps).

    Returns the dict the CLI's --json writes (same keys, same numbers; 'path' is the path given,
    or '<array>'). errors=True adds 'errors': per-pair numpy arrays 'stamps' (int64 ns), 'error'
    (+ 'stamps_end' for RPE, the parts for ASE), as the CLI's --errors CSV.
    Raises InputError, UsageError or ComputeError with the library's messages, options spelled as
    these keywords (e.g. "n_align needs align (se3, sim3, scale, posyaw or full)").
"""


def ape(ref, est, *, align="none", n_align=0, t_max_diff=_T_MAX_DIFF, t_offset=_T_OFFSET, association="nearest",
        relation="trans_part", errors=False, **inputs):
    return _evaluate("ape", ref, est, errors, inputs, dict(
        align=align, n_align=n_align, t_max_diff=t_max_diff, t_offset=t_offset, association=association,
        relation=relation))


def rpe(ref, est, *, align="none", n_align=0, t_max_diff=_T_MAX_DIFF, t_offset=_T_OFFSET, association="nearest",
        relation="trans_part", delta=1.0, delta_unit="frames", all_pairs=False, kitti_drift=False,
        errors=False, **inputs):
    return _evaluate("rpe", ref, est, errors, inputs, dict(
        align=align, n_align=n_align, t_max_diff=t_max_diff, t_offset=t_offset, association=association,
        relation=relation, delta=delta, delta_unit=delta_unit, all_pairs=all_pairs, kitti_drift=kitti_drift))


def ase(ref, est, *, align="none", n_align=0, t_max_diff=_T_MAX_DIFF, t_offset=_T_OFFSET, association="nearest",
        gt_velocity="auto", velocity_frame="world", pose_only=False, errors=False, **inputs):
    return _evaluate("ase", ref, est, errors, inputs, dict(
        align=align, n_align=n_align, t_max_diff=t_max_diff, t_offset=t_offset, association=association,
        gt_velocity=gt_velocity, velocity_frame=velocity_frame, pose_only=pose_only))


ape.__doc__ = """Absolute pose error, as ``cheval ape`` (evo_ape's definitions and numbers).

    relation: 'trans_part', 'rot_part', 'full', 'angle_deg', 'angle_rad' or 'point_distance'.
""" + _COMMON_DOC
rpe.__doc__ = """Relative pose error, as ``cheval rpe`` (evo_rpe's definitions and numbers).

    relation as ape(); delta and delta_unit ('frames', 'meters', 'degrees', 'radians' or evo's
    f, m, d, r): the pair distance; all_pairs: overlapping pairs from every pose; kitti_drift: also
    the KITTI drift (% and deg/m over 100..800 m).
""" + _COMMON_DOC
ase.__doc__ = """Absolute State Error on SE_2(3), as ``cheval ase`` (rotation, position, velocity; C-ASE).

    gt_velocity: 'auto' (its columns, else Chebyshev), 'given', 'chebyshev' or 'central';
    velocity_frame: the estimate's velocity columns are 'world' or 'body'; pose_only: rotation +
    position only, for estimates without velocity.
""" + _COMMON_DOC


def simulate_quadrotor(scenario, output, *, seed=1, duration=10.0, vehicle=DEFAULT_VEHICLE):
    """Simulates a quadrotor flight seen by a camera and writes its data folder, as ``cheval sim
    quadrotor`` (docs/estimator.md): vehicle.json, landmarks.csv, measurements.csv, initial.csv and
    truth.csv in ``output``. scenario: 'hover', 'line', 'circle', 'figure8', 'lissajous' or
    'aggressive'; vehicle: a vehicle + camera JSON file.
    """
    _cheval.simulate_quadrotor(scenario, _path(output, "output"), seed, float(duration), _path(vehicle, "vehicle"))


def estimate_quadrotor(*, scenario=None, data=None, seed=1, duration=10.0, vehicle=None, degree=None, segment=None):
    """States and rotor speeds of a quadrotor from camera measurements and its dynamics, as ``cheval
    estimate quadrotor`` (docs/estimator.md). Give a data folder (``data=``, as written by
    simulate_quadrotor; its vehicle.json unless ``vehicle`` is given) or a scenario to simulate
    (``scenario=``, with ``seed``, ``duration`` and ``vehicle``, default DEFAULT_VEHICLE).
    ``degree`` and ``segment`` (s) override the CLI's defaults (degree 4, 0.2 s segments).

    Returns the dict of ``cheval estimate quadrotor --json`` (states, segments, degree, iterations,
    seconds, converged and, with a ground truth, rotor_error_rpm, rotor_error_percent,
    position_rmse_m, rotation_rmse_deg, velocity_rmse_mps) plus 'estimate': numpy arrays 'times'
    (n,) s, 'positions' (n, 3), 'quaternions' (n, 4) x y z w (R_world_body), 'velocities' (n, 3)
    world m/s, 'angular_velocities' (n, 3) body rad/s, 'rotor_speeds' (n, 4) rad/s, at the truth's
    times (else every 10 ms).
    """
    if scenario is not None and vehicle is None:
        vehicle = DEFAULT_VEHICLE
    text, arrays = _cheval.estimate_quadrotor(scenario, None if data is None else _path(data, "data"), seed,
                                              float(duration), None if vehicle is None else _path(vehicle, "vehicle"),
                                              None if degree is None else int(degree),
                                              None if segment is None else float(segment))
    result = _json.loads(text)
    result["estimate"] = arrays
    return result
