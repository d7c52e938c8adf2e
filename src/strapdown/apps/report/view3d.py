"""The 3D view of the body's attitude: a model aircraft with its body axes, in the named reference frame.

The model is drawn with an orthographic camera on a plain 2D canvas (Bokeh patches and segments), projected in
the browser by ``view3d.js`` whenever the time slider moves, the play button steps it, or a drag turns the
camera; it needs no WebGL, so it draws in every browser, headless ones and machines without a GPU included.
:func:`scene` is the same projection in numpy: it gives the page its first picture, and the browser tests check
the script's against it.

Frames: the model is built in FRD axes (nose forward, right wing, down) and turned into the run's body axes
(``frame_matrix("FRD", body)``), so its nose is the body's forward axis whatever the letters; attitudes map body
vectors to the reference frame (``v_ref = q v_body q*``), which is shown with its own axes, re-expressed for
display in east-north-up (``frame_matrix(frame, "ENU")``) so that up is up on the screen.  The body axes are
drawn in colour (x red, y green, z blue) and labelled with their letters (``x F``), the reference axes in grey.
"""

from __future__ import annotations

from functools import cache
from importlib import resources

import numpy as np

__all__ = ["CAMERA", "scene", "script", "view_spec"]

#: The first camera: from behind the vehicle's left and above (azimuth from north toward east, elevation), radians.
CAMERA = {"az": float(np.radians(205.0)), "el": float(np.radians(22.0))}  # plain floats: their repr is JS

# The model in FRD: a fuselage (a double pyramid on a square ring), wings, tailplane and fin; each plate is one
# polygon whose first three vertices turn counter-clockwise seen from above (its normal points up, -D).
_V = [
    (1.2, 0.0, 0.0),  # 0 nose
    (-1.0, 0.0, 0.0),  # 1 tail
    (0.25, 0.0, -0.16),  # 2 ring: top
    (0.25, 0.16, 0.0),  # 3 right
    (0.25, 0.0, 0.16),  # 4 bottom
    (0.25, -0.16, 0.0),  # 5 left
    (0.45, 0.0, 0.0),  # 6 wing root, front
    (-0.05, 0.0, 0.0),  # 7 wing root, back
    (0.2, 1.1, 0.0),  # 8 right tip, front
    (0.0, 1.1, 0.0),  # 9 right tip, back
    (0.2, -1.1, 0.0),  # 10 left tip, front
    (0.0, -1.1, 0.0),  # 11 left tip, back
    (-0.7, 0.0, 0.0),  # 12 tailplane root, front
    (-0.98, 0.0, 0.0),  # 13 tailplane root, back
    (-0.88, 0.42, 0.0),  # 14 tailplane right tip
    (-0.88, -0.42, 0.0),  # 15 tailplane left tip
    (-0.62, 0.0, 0.0),  # 16 fin, front foot
    (-1.0, 0.0, -0.48),  # 17 fin top, back
    (-0.86, 0.0, -0.48),  # 18 fin top, front
]
_BODY_GREY, _TOP, _BOTTOM = "#b8bcc4", "#e9eef5", "#4a5160"
_RIGHT, _LEFT, _FIN = "#2e9d4f", "#cc3b3b", "#d9a441"  # navigation colours: green right, red left
# (vertices, colour seen from its front, colour from its back)
_FACES = [
    ((0, 2, 3), _BODY_GREY, _BODY_GREY),
    ((0, 3, 4), _BODY_GREY, _BODY_GREY),
    ((0, 4, 5), _BODY_GREY, _BODY_GREY),
    ((0, 5, 2), _BODY_GREY, _BODY_GREY),
    ((1, 3, 2), _BODY_GREY, _BODY_GREY),
    ((1, 4, 3), _BODY_GREY, _BODY_GREY),
    ((1, 5, 4), _BODY_GREY, _BODY_GREY),
    ((1, 2, 5), _BODY_GREY, _BODY_GREY),
    ((6, 7, 9, 8), _RIGHT, _BOTTOM),  # right wing: top green, underside dark
    ((7, 6, 10, 11), _LEFT, _BOTTOM),
    ((12, 13, 14), _TOP, _BOTTOM),
    ((13, 12, 15), _TOP, _BOTTOM),
    ((16, 17, 18, 1), _FIN, _FIN),
]
_AXIS_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")
# the horizon: a circle in the reference frame's horizontal plane, in display axes (east, north, up)
_RING = 1.7 * np.column_stack(
    [np.cos(np.linspace(0, 2 * np.pi, 49)), np.sin(np.linspace(0, 2 * np.pi, 49)), np.zeros(49)]
)


@cache
def _script() -> str:
    return resources.files(__package__).joinpath("view3d.js").read_text(encoding="utf-8")


def view_spec(frame: str, body: str) -> dict:
    """The model, its axes and the reference axes for the script: vertices in ``body`` axes, the display matrix.

    Parameters
    ----------
    frame : str
        The reference frame of the attitudes (``"NED"``, ``"ENU"``, ...).
    body : str
        Their body axes (``"FRD"``, ``"FLU"``, ...).

    Returns
    -------
    dict
        ``vertices`` (body axes), ``faces``, ``front``/``back`` colours, ``display`` (row-major 3x3: reference to
        east-north-up), ``body_axes`` and ``reference_axes`` (vector, colour, label).

    Examples
    --------
    >>> from strapdown.apps.report.view3d import view_spec
    >>> spec = view_spec("NED", "FRD")
    >>> spec["vertices"][0], [a["label"] for a in spec["reference_axes"]]
    ([1.2, 0.0, 0.0], ['N', 'E', 'D'])
    """
    from ...rotations.frames import frame_matrix

    to_body = frame_matrix("FRD", body)  # v_body = M v_frd
    vertices = (np.array(_V) @ to_body.T).round(12) + 0.0
    letters_body = body.upper()
    eye = np.eye(3)
    return {
        "vertices": vertices.tolist(),
        "faces": [list(f) for f, _, _ in _FACES],
        "front": [c for _, c, _ in _FACES],
        "back": [c for _, _, c in _FACES],
        "display": frame_matrix(frame, "ENU").reshape(-1).tolist(),
        "body_axes": [
            {"v": (1.5 * eye[i]).tolist(), "color": _AXIS_COLOURS[i], "label": f"{'xyz'[i]} {letters_body[i]}"}
            for i in range(3)
        ],
        "reference_axes": [
            {"v": (1.9 * eye[i]).tolist(), "color": "#8a8f98", "label": frame.upper()[i]} for i in range(3)
        ],
        "ring": _RING.tolist(),
    }


def _basis(camera: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    az, el = camera["az"], camera["el"]
    c = np.array([np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)])
    r = np.array([-np.cos(az), np.sin(az), 0.0])
    return c, r, np.cross(r, -c)


def _rotate(q, v: np.ndarray) -> np.ndarray:
    from ...rotations.quaternion import rotate

    return rotate(np.asarray(q, dtype=np.float64), v)


def scene(spec: dict, q, camera: dict | None = None) -> dict:
    """The projected model and axes of attitude ``q``: what ``view3d.js`` draws (same order, same numbers).

    Parameters
    ----------
    spec : dict
        From :func:`view_spec`.
    q : array_like, shape (4,)
        Attitude, body to the reference frame.
    camera : dict, optional
        ``az`` and ``el`` in radians (default :data:`CAMERA`).

    Returns
    -------
    dict
        ``model`` (``xs``, ``ys``, ``color`` of each face, far ones first), ``axes`` (segments from the origin
        and their labels: reference axes first, then body axes) and ``ring`` (``x``, ``y`` of the horizon).

    Examples
    --------
    >>> from strapdown.apps.report.view3d import scene, view_spec
    >>> s = scene(view_spec("ENU", "FLU"), [1.0, 0, 0, 0], {"az": 0.0, "el": 0.0})   # seen from the north
    >>> s["axes"]["text"][3:]                                 # the identity: forward east, left north, up
    ['x F', 'y L', 'z U']
    >>> [round(v, 9) + 0.0 for v in s["axes"]["x1"][3:]], [round(v, 9) + 0.0 for v in s["axes"]["y1"][3:]]
    ([-1.5, 0.0, 0.0], [0.0, 0.0, 1.5])
    """
    camera = CAMERA if camera is None else camera
    c, r, u = _basis(camera)
    display = np.array(spec["display"]).reshape(3, 3)
    world = _rotate(q, np.array(spec["vertices"])) @ display.T
    screen = np.column_stack([world @ r, world @ u, world @ c])
    order = []
    colours = []
    for i, face in enumerate(spec["faces"]):
        pts = world[face]
        n = np.cross(pts[1] - pts[0], pts[2] - pts[0])
        facing = float(n @ c / (np.linalg.norm(n) or 1.0))
        colour = spec["front"][i] if facing >= 0 else spec["back"][i]
        order.append((float(screen[face, 2].mean()), i))
        colours.append(_shade(colour, 0.6 + 0.4 * abs(facing)))
    order.sort()
    model = {
        "xs": [screen[spec["faces"][i], 0].tolist() for _, i in order],
        "ys": [screen[spec["faces"][i], 1].tolist() for _, i in order],
        "color": [colours[i] for _, i in order],
    }
    axes = {k: [] for k in ("x0", "y0", "x1", "y1", "color", "tx", "ty", "text")}
    ref = [(display @ np.array(a["v"]), a) for a in spec["reference_axes"]]
    bod = [(display @ _rotate(q, np.array(a["v"])), a) for a in spec["body_axes"]]
    for v, a in ref + bod:
        x, y = float(v @ r), float(v @ u)
        for key, value in zip(("x0", "y0", "x1", "y1", "color"), (0.0, 0.0, x, y, a["color"]), strict=True):
            axes[key].append(value)
        axes["tx"].append(x * 1.08)
        axes["ty"].append(y * 1.08)
        axes["text"].append(a["label"])
    ring = np.array(spec["ring"])
    return {"model": model, "axes": axes, "ring": {"x": (ring @ r).tolist(), "y": (ring @ u).tolist()}}


def _shade(colour: str, k: float) -> str:
    """As ``SD.shade`` of the script: darkened (k < 1) or lightened toward white (k > 1), rounded per channel."""
    n = int(colour[1:], 16)
    rgb = [(n >> 16) & 255, (n >> 8) & 255, n & 255]

    def f(c):
        # JavaScript's Math.round: half up
        value = np.floor(c * k + 0.5) if k <= 1 else np.floor(c + (255 - c) * (k - 1) + 0.5)
        return int(min(255, max(0, value)))

    return "#" + "".join(f"{f(c):02x}" for c in rgb)


def script() -> str:
    """The script of the view (the ``SD`` object), to put in front of each callback's own code."""
    return _script()
