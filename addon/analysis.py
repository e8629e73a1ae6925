"""Surface analysis on the limit mesh: the exact principal curvatures the library computes
(ccn_limit_mesh.curvatures) as point attributes, and a colour attribute showing one of them.

With the cage's Curvature setting (Analysis) on, every sync of a proxy writes:
* `curvature_gaussian` = k1 k2 and `curvature_mean` = (k1 + k2) / 2 (FLOAT, POINT), with the
  sign of the library: positive where the surface bends away from its normal;
* `curvature_undefined` (BOOLEAN, POINT): the library's NaN flag (an extraordinary point without
  a cap, where the curvature is unbounded; creases, corners); the two values are 0 there;
* `curvature_color` (FLOAT_COLOR, POINT, the active colour attribute: Solid shading > Attribute
  shows it): the chosen quantity (Gaussian, mean or max |k|) blue (negative) - white (0) - red
  (positive) over a symmetric range, the 98th percentile of its magnitude (a few vertices near
  an EV without a cap would otherwise take the whole scale); flagged vertices magenta.
Turned off, the attributes are removed. The range is kept on the proxy mesh (RANGE_PROP) for the
panel's legend.
"""
import numpy as np

from . import attrs, compat

NAMES = ("curvature_gaussian", "curvature_mean", "curvature_undefined", "curvature_color")
RANGE_PROP = "ccnurbs_curvature_range"
NEG = np.array((0.10, 0.35, 1.00, 1.0), np.float32)
ZERO = np.array((1.00, 1.00, 1.00, 1.0), np.float32)
POS = np.array((1.00, 0.15, 0.10, 1.0), np.float32)
FLAG = np.array((1.00, 0.00, 1.00, 1.0), np.float32)


_T = np.linspace(-1.0, 1.0, 1025, dtype=np.float32)[:, None]
# the colour table: 1025 steps from -1 to 1, then the flag's colour (index 1025)
LUT = np.vstack([np.where(_T < 0, ZERO + (NEG - ZERO) * -_T, ZERO + (POS - ZERO) * _T),
                 FLAG[None, :]]).astype(np.float32)
RANGE_SAMPLES = 16384  # the range is the percentile of at most this many evenly spaced vertices


def colors(q, bad):
    """RGBA per vertex (N, 4) float32 and the symmetric range used: the 98th percentile of |q|
    over the defined vertices (of an even subsample of at most RANGE_SAMPLES on big meshes, the
    same value to a fraction of a colour step; a full sort would cost more than the evaluation);
    a gather from the table, not arithmetic on N x 4 arrays."""
    step = max(1, len(q) // RANGE_SAMPLES)
    mag = np.abs(q[::step][~bad[::step]])
    if len(mag):
        k = min(len(mag) - 1, int(0.98 * (len(mag) - 1) + 0.5))
        r = float(np.partition(mag, k)[k])
    else:
        r = 0.0
    if r > 0:
        t = np.asarray(q, np.float32) * np.float32(512.0 / r)
        t += np.float32(512.5)
        np.clip(t, 0.0, 1024.0, out=t)
        idx = t.astype(np.int32)
    else:
        idx = np.full(len(q), 512, np.int32)
    idx[bad] = len(LUT) - 1
    return np.take(LUT, idx, axis=0), r


def clear(me):
    for name in NAMES:
        a = me.attributes.get(name)
        if a is not None:
            me.attributes.remove(a)
    if RANGE_PROP in me:
        del me[RANGE_PROP]


def write(me, curv, mode):
    """The attributes of `mode` ('NONE' removes them) from the evaluation's (N, 2) curvatures."""
    if mode == 'NONE' or curv is None:
        clear(me)
        return
    # float32, what the attributes hold, each curvature a contiguous row (NaN: flagged; both are
    # NaN together, and a value beyond float32 is flagged with them)
    with np.errstate(invalid='ignore', over='ignore'):
        k = curv.T.astype(np.float32)
        k1, k2 = k[0], k[1]
        mean = k1 + k2
        bad = ~np.isfinite(mean)
        mean *= np.float32(0.5)
        gauss = k1 * k2
        q = gauss if mode == 'GAUSSIAN' else mean if mode == 'MEAN' else \
            np.maximum(k1, -k2)  # max |k| (k1 >= k2)
        for a in (gauss, mean, q) if mode == 'MAX' else (gauss, mean):  # q is one of them
            np.copyto(a, 0.0, where=bad)
    for name, kind, prop, vals in ((NAMES[0], 'FLOAT', "value", gauss),
                                   (NAMES[1], 'FLOAT', "value", mean),
                                   (NAMES[2], 'BOOLEAN', "value", bad)):
        attrs.attribute(me, name, kind, 'POINT').data.foreach_set(prop, vals)
    c, r = colors(q, bad)
    attrs.attribute(me, NAMES[3], 'FLOAT_COLOR', 'POINT').data.foreach_set("color",
                                                                          c.ravel())
    compat.set_active_color(me, NAMES[3])
    me[RANGE_PROP] = r


# ---- highlight lines ----------------------------------------------------------------------

MATCAP_PREFIX = "ccnurbs_highlight_lines"
DIRECTIONS = ('RINGS', 'HORIZONTAL', 'VERTICAL')


def matcap_name(direction='RINGS', stripes=15):
    return "%s_%s_%d.png" % (MATCAP_PREFIX, direction.lower(), stripes)


def stripe_matcap(path, direction='RINGS', stripes=15, size=512):
    """A highlight-line matcap. RINGS: light and dark stripes by the angle between the normal
    and the view direction (every point facing the viewer in the middle of its own closed
    stripe); HORIZONTAL / VERTICAL: zebra stripes by the normal's up / sideways component (the
    reflection of a striped wall). `stripes`: light-dark pairs across the hemisphere. Kinks or
    wobbles in the stripes show curvature defects the shading hides."""
    import bpy
    y, x = np.mgrid[0:size, 0:size]
    nx, ny = (x + 0.5) / size * 2 - 1, (y + 0.5) / size * 2 - 1
    r = np.sqrt(nx * nx + ny * ny)
    if direction == 'HORIZONTAL':
        phase = np.degrees(np.arcsin(np.clip(ny, -1, 1))) + 90.0
    elif direction == 'VERTICAL':
        phase = np.degrees(np.arcsin(np.clip(nx, -1, 1))) + 90.0
    else:
        phase = np.degrees(np.arcsin(np.clip(r, 0, 1)))
    period = (180.0 if direction != 'RINGS' else 90.0) / stripes
    c = np.cos(2 * np.pi * phase / period)
    px = np.abs(np.gradient(phase, axis=1)) + np.abs(np.gradient(phase, axis=0))
    band = np.clip(0.5 + c / (2 * np.pi / period * np.maximum(px, 1e-3) * 2), 0, 1)  # antialiased
    v = np.where(r <= 1, 0.12 + 0.83 * band, 0.0)
    rgba = np.dstack([v, v, v, np.ones_like(v)]).astype(np.float32)
    img = bpy.data.images.new(".ccnurbs stripes", size, size, alpha=True, float_buffer=True)
    try:
        img.pixels.foreach_set(rgba.ravel())
        img.filepath_raw = path
        img.file_format = 'PNG'
        img.save()
    finally:
        bpy.data.images.remove(img)
    return path


def highlight_matcap(direction='RINGS', stripes=15):
    """The studio light name of the add-on's stripe matcap of that direction and density, made
    and loaded on first use (in Blender's user data folder; nothing is stored in the .blend)."""
    import os
    import bpy
    name = matcap_name(direction, stripes)
    lights = bpy.context.preferences.studio_lights
    for sl in lights:
        if sl.name == name:
            return sl.name
    folder = bpy.utils.user_resource('DATAFILES', path="ccnurbs", create=True)
    path = os.path.join(folder, name)
    if not os.path.exists(path):
        stripe_matcap(path, direction, stripes)
    sl = lights.load(path, 'MATCAP')
    return sl.name if sl is not None else None


def show_highlight_lines(context, on=True, direction='RINGS', stripes=15):
    """Solid shading with the stripe matcap (on) or back to Studio lighting, in every 3D view
    of the window and in the scene's Workbench render settings. Returns the matcap's name."""
    name = highlight_matcap(direction, stripes) if on else None
    shadings = [context.scene.display.shading] if context.scene is not None else []
    screen = getattr(context, "screen", None)
    for area in (screen.areas if screen is not None else []):
        if area.type == 'VIEW_3D':
            shadings += [sp.shading for sp in area.spaces if sp.type == 'VIEW_3D']
    for sh in shadings:
        if on and name:
            sh.light = 'MATCAP'
            sh.studio_light = name
        elif not on and sh.light == 'MATCAP' and sh.studio_light.startswith(MATCAP_PREFIX):
            sh.light = 'STUDIO'
    return name
