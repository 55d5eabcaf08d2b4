"""``moreau animate``: an animation of a ``moreau run`` output, drawn from the scene's shapes.

The run's sidecar (``<tag>.json``, written by ``moreau run``) names the scene
and its parameters; the table (``<tag>.csv``) holds the SI coordinates
``q_i``, the time ``t`` and each contact's forces ``force_N_i``,
``force_T_i``. Each frame draws :meth:`Scene.shapes` at one sample: the bodies,
the contact points (dots) and the contact forces (arrows, scaled to the
largest force of the run). The writer is matplotlib's: Pillow for a ``.gif``,
ffmpeg for an ``.mp4`` (where it is installed).

Examples
--------
From the shell: ``moreau run --scene bouncing-ball --duration 2 --out run1`` then
``moreau animate run1 --out ball.gif``. The frames are spread evenly in time:

>>> frame_indices([0.0, 0.5, 1.0, 1.5, 2.0], 3).tolist()
[0, 2, 4]
"""

import csv
import glob
import json
import os

import numpy as np
from PIL import Image

from ..errors import InputError
from ..model.registry import make_scene

__all__ = ["load_run", "animate_run", "write_animation", "frame_indices"]


def _find(run):
    """The table and sidecar of a ``moreau run`` output: a folder holding one, or the CSV itself."""
    if os.path.isfile(run) and run.endswith(".csv"):
        table = run
    elif os.path.isdir(run):
        tables = []
        for path in sorted(glob.glob(os.path.join(run, "*.csv"))):
            side = os.path.splitext(path)[0] + ".json"
            try:
                with open(side) as fh:
                    if json.load(fh).get("command") == "moreau run":
                        tables.append(path)
            except (OSError, ValueError, AttributeError):
                continue
        if not tables:
            raise InputError(f"`RUN` folder {run!r} holds no output of `moreau run` (a .csv "
                             "with its .json sidecar)")
        if len(tables) > 1:
            raise InputError(f"`RUN` folder {run!r} holds {len(tables)} runs; name one: "
                             + ", ".join(os.path.basename(t) for t in tables))
        table = tables[0]
    else:
        raise InputError(f"`RUN` must be the output folder of `moreau run` or one of its .csv "
                         f"tables; got {run!r}")
    side = os.path.splitext(table)[0] + ".json"
    try:
        with open(side) as fh:
            meta = json.load(fh)
    except (OSError, ValueError) as exc:
        raise InputError(f"`RUN`: the sidecar {side!r} cannot be read: {exc}") from None
    return table, meta


def load_run(run):
    """``(scene, meta, columns)`` of a ``moreau run`` output; ``columns`` maps names (no units) to arrays."""
    table, meta = _find(run)
    if "scene" not in meta:
        raise InputError(f"`RUN`: the sidecar of {table!r} names no scene")
    scene = make_scene(meta["scene"], **(meta.get("parameters") or {}))
    with open(table, newline="") as fh:
        reader = csv.reader(fh)
        header = [h.split(" [")[0] for h in next(reader)]
        rows = list(reader)
    cols = {}
    for j, name in enumerate(header):
        if name.startswith("regime"):
            continue
        cols[name] = np.array([float(r[j]) for r in rows])
    missing = [f"q_{i}" for i in range(scene.ndof) if f"q_{i}" not in cols] + (
        [] if "t" in cols else ["t"])
    if missing:
        raise InputError(f"`RUN`: the table {table!r} lacks the columns {', '.join(missing)}")
    return scene, meta, cols


def frame_indices(t, max_frames):
    """Indices of at most ``max_frames`` samples spread evenly in time (first and last included).

    Examples
    --------
    >>> frame_indices([0.0, 1.0, 2.0, 3.0, 4.0], 3).tolist()
    [0, 2, 4]
    """
    t = np.asarray(t, dtype=float)
    if len(t) <= max_frames:
        return np.arange(len(t))
    idx = np.searchsorted(t, np.linspace(t[0], t[-1], max_frames))
    return np.unique(np.minimum(idx, len(t) - 1))


def _bounds(frames):
    pts = []
    for shapes in frames:
        for s in shapes:
            if s["kind"] == "circle":
                (x, y), r = s["centre"], s["radius"]
                pts += [(x - r, y - r), (x + r, y + r)]
            elif "points" in s:
                pts += s["points"]
            elif "point" in s:
                pts.append(s["point"])
    p = np.array(pts)
    lo, hi = p.min(axis=0), p.max(axis=0)
    span = max(float(np.max(hi - lo)), 1e-300)
    pad = 0.15 * span
    return lo - pad, hi + pad, span


def animate_run(run, out, fps=20, max_frames=100, force=False):
    """Write the animation of the ``moreau run`` output ``run`` to ``out`` (.gif or .mp4).

    Returns ``(path, frames)``. Refuses, before drawing, an ``out`` that
    exists (unless ``force``), a suffix other than .gif/.mp4, an .mp4 where
    ffmpeg is missing, and a scene that cannot draw itself.
    """
    _check_out(out, fps, max_frames, force)
    scene, meta, cols = load_run(run)
    return write_animation(scene, cols, out, f"{meta['scene']} ({meta.get('scheme', '?')})",
                           fps=fps, max_frames=max_frames)


def _check_out(out, fps, max_frames, force):
    from matplotlib import animation

    ext = os.path.splitext(str(out))[1].lower()
    if ext not in (".gif", ".mp4"):
        raise InputError(f"`--out` must end in .gif or .mp4, got {out!r}")
    if isinstance(fps, bool) or not isinstance(fps, int) or fps < 1:
        raise InputError(f"`--fps` must be an integer >= 1, got {fps!r}")
    if isinstance(max_frames, bool) or not isinstance(max_frames, int) or max_frames < 2:
        raise InputError(f"`--frames` must be an integer >= 2, got {max_frames!r}")
    if os.path.exists(out) and not force:
        raise InputError(f"`--out` {out!r} exists: give `--force` to replace it")
    folder = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise InputError(f"`--out`: the folder {folder!r} does not exist or is not writable")
    if ext == ".mp4" and not animation.FFMpegWriter.isAvailable():
        raise InputError("`--out` .mp4 needs ffmpeg, which is not installed here; write a .gif "
                         "(Pillow) instead")


def write_animation(scene, cols, out, title, fps=20, max_frames=100):
    """Draw ``scene`` along the SI columns ``cols`` (``t``, ``q_i``, ``force_N_i``, ``force_T_i``).

    ``cols`` maps the names of ``Scene.si_columns`` (without units) to
    arrays, as :func:`load_run` reads them. A contact shape marked
    ``"open"`` is not drawn. Writes ``out`` (.gif: Pillow, .mp4: ffmpeg) and
    returns ``(path, frames)``.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import animation
    from matplotlib.patches import Circle, Polygon

    ext = os.path.splitext(str(out))[1].lower()
    t = cols["t"]
    idx = frame_indices(t, max_frames)
    q = np.column_stack([cols[f"q_{i}"] for i in range(scene.ndof)])
    frames = [scene.shapes(q[k], float(t[k])) for k in idx]
    nc = scene.ncontacts
    fN = np.column_stack([cols.get(f"force_N_{i}", np.zeros(len(t))) for i in range(nc)]) \
        if nc else np.zeros((len(t), 0))
    fT = np.column_stack([cols.get(f"force_T_{i}", np.zeros(len(t))) for i in range(nc)]) \
        if nc else np.zeros((len(t), 0))
    fmax = float(np.max(np.hypot(fN, fT))) if nc else 0.0
    lo, hi, span = _bounds(frames)
    arrow = 0.25 * span / fmax if fmax > 0 else 0.0

    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    drawn = []

    def draw(n):
        # only the bodies change from frame to frame: the axes are drawn once
        while drawn:
            drawn.pop().remove()
        k = idx[n]
        ax.set_title(f"{title}  t = {t[k]:.4g} s", fontsize=9)
        for s in frames[n]:
            colour = "0.6" if s.get("role") in ("ground", "stator") else "C0"
            if s["kind"] == "circle":
                drawn.append(ax.add_patch(Circle(s["centre"], s["radius"], fc=colour, ec="k",
                                                 alpha=0.8)))
            elif s["kind"] == "polygon":
                drawn.append(ax.add_patch(Polygon(s["points"], closed=True, fc=colour, ec="k",
                                                  alpha=0.8)))
            elif s["kind"] == "line":
                xs, ys = zip(*s["points"])
                drawn.extend(ax.plot(xs, ys, "-", color="k" if colour != "C0" else "C0", lw=2))
            elif s["kind"] == "contact" and not s.get("open"):
                # (a candidate the scene marks open, far from touching, carries no force)
                (x, y), i = s["point"], s["index"]
                drawn.extend(ax.plot([x], [y], "o", color="C3", ms=4))
                f = fN[k, i] * np.array(s["normal"]) + fT[k, i] * np.array(s["tangent"])
                if arrow and np.hypot(*f) > 0:
                    drawn.append(ax.annotate(
                        "", xy=(x + arrow * f[0], y + arrow * f[1]), xytext=(x, y),
                        arrowprops=dict(arrowstyle="->", color="C3", lw=1.5)))
        return drawn

    try:
        if ext == ".gif":
            _write_gif(fig, ax, draw, len(frames), out, fps)
        else:
            writer = animation.FFMpegWriter(fps=fps)
            # the writer's own loop: one draw per frame (FuncAnimation.save draws each twice)
            with writer.saving(fig, out, dpi=80):
                for n in range(len(frames)):
                    draw(n)
                    writer.grab_frame()
    finally:
        plt.close(fig)
    return out, len(frames)


def _write_gif(fig, ax, draw, count, out, fps):
    # the axes, their ticks and labels are drawn once and each frame's bodies, contacts and
    # title over a copy of them (a full draw a frame spent two thirds of its time on the axes)
    fig.set_dpi(80)
    canvas = fig.canvas
    ax.set_title(" ", fontsize=9)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    images = []
    for n in range(count):
        canvas.restore_region(background)
        for artist in draw(n) + [ax.title]:
            ax.draw_artist(artist)
        images.append(Image.fromarray(np.asarray(canvas.buffer_rgba())).convert("RGB"))
    images[0].save(out, save_all=True, append_images=images[1:], duration=int(1000 / fps),
                   loop=0)
