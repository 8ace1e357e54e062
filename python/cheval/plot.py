"""Figures for papers: evo's and rpg_trajectory_evaluation's plots from cheval's evaluations, with
matplotlib (docs/report.md, "Figures for papers")::

    import cheval.plot as cp
    fig = cp.trajectory("gt.csv", {"VINS": "vins.txt", "ORB": "orb.txt"}, color_by_error=True)
    cp.save(fig, "trajectory.pdf")                      # .pdf, .svg or .png
    cp.save(cp.rpe_per_distance("gt.csv", ["a.txt", "b.txt"]), "rpe.pdf")

Every function takes the reference and the estimates (a path, a Trajectory, a mapping of arrays, a
list of them, or a dict label -> one of them; labels default to the file names) and the evaluation
options of cheval.ape (align defaults to 'se3', as `cheval report`), and returns a
matplotlib.figure.Figure (no pyplot: no window, no global state). The numbers are those of
cheval.ape / cheval.rpe with the same options. From the shell, the same files:
``python3 -m cheval.plot REF EST [EST ...] -o FOLDER [--format pdf|svg|png]``.
"""

import argparse
import math
import os
import sys
import tempfile

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure

import cheval

__all__ = ["trajectory", "errors_over_time", "distribution", "rpe_per_distance", "rpe_distances", "save", "main"]

_COLORS = ["#0969da", "#cf222e", "#1a7f37", "#8250df", "#bc4c00", "#1b7c83", "#bf3989", "#6e7781"]
_FORMATS = ("pdf", "svg", "png")


def _label_of(source, k):
    if isinstance(source, (str, os.PathLike)):
        return os.path.basename(os.fspath(source))
    path = getattr(source, "path", None)
    return os.path.basename(path) if path and path != "<array>" else f"estimate {k + 1}"


def _estimates(estimates):
    """[(label, source)] of one estimate, a list of them, or a dict label -> estimate."""
    if isinstance(estimates, dict):
        return list(estimates.items())
    if isinstance(estimates, (list, tuple)):
        return [(_label_of(e, k), e) for k, e in enumerate(estimates)]
    return [(_label_of(estimates, 0), estimates)]


def _read(source):
    return source if isinstance(source, cheval.Trajectory) else cheval.read(source) \
        if isinstance(source, (str, os.PathLike)) else cheval.Trajectory(**source)


def _aligned(ref, est, options):
    """The estimate's positions (n, 3) after the alignment of cheval.align with `options`."""
    a = cheval.align(ref, est, method=options.get("align", "se3"), n_align=options.get("n_align", 0),
                     t_max_diff=options.get("t_max_diff", 0.01), t_offset=options.get("t_offset", 0.0))
    p = _read(est).positions
    return (a["scale"] * p) @ np.asarray(a["rotation"]).T + np.asarray(a["translation"])


def _options(align, kwargs):
    options = {"align": align}
    options.update(kwargs)
    return options


def _origin(ref):
    stamps = _read(ref).stamps
    return int(stamps.min()) if stamps is not None and len(stamps) else 0


def trajectory(ref, estimates, *, plane="xy", color_by_error=False, align="se3", **options):
    """evo's trajectory plot (evo_traj / evo_ape --plot): the reference dashed grey, each aligned
    estimate in its colour, start (circle) and end (square) markers, equal axes; with
    color_by_error the first estimate's paired poses coloured by their APE (evo's
    --plot_colormap_max style colour bar), and only it: evo draws one estimate coloured by its
    error. plane: 'xy', 'xz' or 'yz'."""
    axes = {"x": 0, "y": 1, "z": 2}
    if len(plane) != 2 or any(c not in axes for c in plane):
        raise cheval.UsageError(f"plane must be 'xy', 'xz' or 'yz', got {plane!r}")
    i, j = axes[plane[0]], axes[plane[1]]
    options = _options(align, options)
    fig = Figure(figsize=(6.4, 5.2), constrained_layout=True)
    ax = fig.add_subplot()
    r = _read(ref).positions
    ax.plot(r[:, i], r[:, j], "--", color="0.45", lw=1.2, label="reference")
    listed = _estimates(estimates)
    for k, (label, est) in enumerate(listed[:1] if color_by_error else listed):
        p = _aligned(ref, est, options)
        color = _COLORS[k % len(_COLORS)]
        if color_by_error and k == 0:
            result = cheval.ape(ref, est, errors=True, **options)
            paired = p[cheval.associate(ref, est, t_max_diff=options.get("t_max_diff", 0.01),
                                        t_offset=options.get("t_offset", 0.0))["est"]]
            segments = np.stack([paired[:-1][:, [i, j]], paired[1:][:, [i, j]]], axis=1)
            lines = LineCollection(segments, cmap="viridis", linewidths=2, label=label)
            lines.set_array(np.asarray(result["errors"]["error"])[1:])
            ax.add_collection(lines)
            fig.colorbar(lines, ax=ax, label=f"APE ({result['metric']['unit'] or 'unit-less'})")
        else:
            ax.plot(p[:, i], p[:, j], color=color, lw=1.2, label=label)
        ax.plot(p[0, i], p[0, j], "o", color=color, ms=6, mec="white")
        ax.plot(p[-1, i], p[-1, j], "s", color=color, ms=6, mec="white")
    ax.plot(r[0, i], r[0, j], "o", color="0.3", ms=6, mec="white")
    ax.plot(r[-1, i], r[-1, j], "s", color="0.3", ms=6, mec="white")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{plane[0]} (m)")
    ax.set_ylabel(f"{plane[1]} (m)")
    ax.legend(loc="best", frameon=False)
    return fig


def errors_over_time(ref, estimates, *, metric="ape", align="se3", **options):
    """evo's error plot (evo_ape --plot): each estimate's per-pair error over time (s from the
    reference's first stamp); with one estimate also its rmse, mean and median as horizontal lines,
    as evo draws them. metric: 'ape' (options of cheval.ape) or 'ase' (of cheval.ase)."""
    evaluate = {"ape": cheval.ape, "ase": cheval.ase}.get(metric)
    if evaluate is None:
        raise cheval.UsageError(f"metric must be 'ape' or 'ase', got {metric!r}")
    options = _options(align, options)
    origin = _origin(ref)
    fig = Figure(figsize=(7.0, 3.6), constrained_layout=True)
    ax = fig.add_subplot()
    listed = _estimates(estimates)
    for k, (label, est) in enumerate(listed):
        result = evaluate(ref, est, errors=True, **options)
        t = (np.asarray(result["errors"]["stamps"]) - origin) / 1e9
        ax.plot(t, result["errors"]["error"], color=_COLORS[k % len(_COLORS)], lw=1, label=label)
        if len(listed) == 1:
            for key, style in (("rmse", "-"), ("mean", "--"), ("median", ":")):
                ax.axhline(result["stats"][key], color="0.35", ls=style, lw=1, label=key)
    unit = result["metric"]["unit"] or "unit-less"
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"{metric.upper()} ({unit})")
    ax.legend(loc="upper left", frameon=False, ncol=min(4, len(listed) + 3))
    return fig


def distribution(ref, estimates, *, kind="box", metric="ape", align="se3", **options):
    """evo_res's box or violin plot of each estimate's per-pair errors (kind 'box' or 'violin';
    boxes as matplotlib draws them: quartiles, whiskers at 1.5 IQR, outliers as points)."""
    if kind not in ("box", "violin"):
        raise cheval.UsageError(f"kind must be 'box' or 'violin', got {kind!r}")
    evaluate = {"ape": cheval.ape, "ase": cheval.ase}[metric]
    options = _options(align, options)
    listed = _estimates(estimates)
    results = [evaluate(ref, est, errors=True, **options) for _, est in listed]
    values = [np.asarray(r["errors"]["error"]) for r in results]
    fig = Figure(figsize=(1.6 + 1.2 * len(listed), 4.0), constrained_layout=True)
    ax = fig.add_subplot()
    positions = np.arange(1, len(listed) + 1)
    if kind == "box":
        parts = ax.boxplot(values, positions=positions, widths=0.5, patch_artist=True)
        for k, box in enumerate(parts["boxes"]):
            box.set(facecolor=_COLORS[k % len(_COLORS)], alpha=0.35)
    else:
        parts = ax.violinplot(values, positions=positions, showmedians=True)
        for k, body in enumerate(parts["bodies"]):
            body.set(facecolor=_COLORS[k % len(_COLORS)], alpha=0.35)
    ax.set_xticks(positions, [label for label, _ in listed])
    ax.set_ylabel(f"{metric.upper()} ({results[0]['metric']['unit'] or 'unit-less'})")
    return fig


def rpe_distances(ref):
    """The RPE distances of `cheval report`: 10..50 % of the reference's path length, floored to
    whole metres from 10 m on, to two significant digits below."""
    p = _read(ref).positions
    length = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    out = []
    for percent in (10, 20, 30, 40, 50):
        d = length * percent / 100
        if d >= 10:
            d = math.floor(d)
        else:
            scale = 10 ** (math.floor(math.log10(d)) - 1)
            d = round(d / scale) * scale
        if d not in out:
            out.append(d)
    return out


def rpe_per_distance(ref, estimates, *, distances=None, align="se3", **options):
    """rpg_trajectory_evaluation's relative error box plots: for each distance (default
    rpe_distances(ref)) one box per estimate in its colour, translation (m) and rotation angle
    (deg) of cheval.rpe with all pairs δ metres of path apart. Boxes without outliers, as rpg."""
    options = _options(align, options)
    distances = rpe_distances(ref) if distances is None else list(distances)
    listed = _estimates(estimates)
    fig = Figure(figsize=(7.0, 5.2), constrained_layout=True)
    axes = fig.subplots(2, 1, sharex=True)
    width = 0.8 / len(listed)
    for row, (relation, ylabel) in enumerate((("trans_part", "translation error (m)"), ("angle_deg", "rotation error (deg)"))):
        ax = axes[row]
        for k, (label, est) in enumerate(listed):
            values = [np.asarray(cheval.rpe(ref, est, relation=relation, delta=d, delta_unit="meters", all_pairs=True,
                                            errors=True, **options)["errors"]["error"]) for d in distances]
            where = np.arange(1, len(distances) + 1) - 0.4 + width * (k + 0.5)
            color = _COLORS[k % len(_COLORS)]
            parts = ax.boxplot(values, positions=where, widths=width * 0.7, sym="", patch_artist=True)
            for name in ("boxes", "whiskers", "caps", "medians"):
                for artist in parts[name]:
                    artist.set(color=color)
            for box in parts["boxes"]:
                box.set(facecolor=color, alpha=0.3)
            ax.plot([], [], color=color, lw=6, alpha=0.5, label=label)
        ax.set_ylabel(ylabel)
        ax.set_xlim(0.5, len(distances) + 0.5)
    axes[0].legend(loc="upper left", frameon=False, ncol=min(4, len(listed)))
    axes[1].set_xticks(np.arange(1, len(distances) + 1), [f"{d:g}" for d in distances])
    axes[1].set_xlabel("distance travelled (m)")
    return fig


def save(figure, path):
    """Writes the figure to `path`, its format from the suffix (.pdf, .svg, .png), atomically (a
    temporary file in the same folder, renamed): a failure leaves no half-written file."""
    suffix = os.path.splitext(os.fspath(path))[1].lower().lstrip(".")
    if suffix not in _FORMATS:
        raise cheval.UsageError(f"{os.fspath(path)}: the figure's format comes from its suffix: .pdf, .svg or .png")
    folder = os.path.dirname(os.path.abspath(path))
    handle, temporary = tempfile.mkstemp(dir=folder, prefix=".cheval-plot-", suffix="." + suffix)
    try:
        with os.fdopen(handle, "wb") as out:
            figure.savefig(out, format=suffix, dpi=200)
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(temporary, 0o666 & ~mask)  # as open() would create it, not mkstemp's 0600
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise


def main(argv=None):
    """python3 -m cheval.plot REF EST [EST ...] -o FOLDER [--format pdf] [--label L ...] [--align se3]:
    writes trajectory, trajectory_xz, trajectory_error, ape_over_time, ape_box, ape_violin and
    rpe_per_distance in FOLDER. Exit 1 for bad arguments, 2 for bad input, 3 when an evaluation is
    impossible, 4 when a file cannot be written (docs/cli.md)."""
    parser = argparse.ArgumentParser(prog="python3 -m cheval.plot", description="Figures for papers from cheval's evaluations")
    parser.add_argument("reference")
    parser.add_argument("estimates", nargs="+")
    parser.add_argument("-o", "--output", required=True, help="the folder to write the figures to")
    parser.add_argument("--format", choices=_FORMATS, default="pdf")
    parser.add_argument("--label", action="append", default=[], help="an estimate's label, once per estimate, in order")
    parser.add_argument("--align", default="se3")
    args = parser.parse_args(argv)
    if args.label and len(args.label) != len(args.estimates):
        parser.error(f"--label given {len(args.label)} time(s) for {len(args.estimates)} estimate(s)")
    labels = args.label or [os.path.basename(e) for e in args.estimates]
    estimates = dict(zip(labels, args.estimates))
    if len(estimates) != len(labels):
        parser.error("two estimates have the same label; give --label for each")
    figures = {
        "trajectory": lambda: trajectory(args.reference, estimates, align=args.align),
        "trajectory_xz": lambda: trajectory(args.reference, estimates, plane="xz", align=args.align),
        "trajectory_error": lambda: trajectory(args.reference, estimates, color_by_error=True, align=args.align),
        "ape_over_time": lambda: errors_over_time(args.reference, estimates, align=args.align),
        "ape_box": lambda: distribution(args.reference, estimates, kind="box", align=args.align),
        "ape_violin": lambda: distribution(args.reference, estimates, kind="violin", align=args.align),
        "rpe_per_distance": lambda: rpe_per_distance(args.reference, estimates, align=args.align),
    }
    try:
        os.makedirs(args.output, exist_ok=True)
        for name, make in figures.items():
            path = os.path.join(args.output, f"{name}.{args.format}")
            save(make(), path)
            print(path)
    except (cheval.UsageError,) as e:
        print(f"cheval.plot: error: {e}", file=sys.stderr)
        return 1
    except cheval.InputError as e:
        print(f"cheval.plot: error: {e}", file=sys.stderr)
        return 2
    except cheval.ComputeError as e:
        print(f"cheval.plot: error: {e}", file=sys.stderr)
        return 3
    except OSError as e:
        print(f"cheval.plot: error: {e}", file=sys.stderr)
        return 4
    return 0


if __name__ == "__main__":
    sys.exit(main())
