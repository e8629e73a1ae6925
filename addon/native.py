"""ctypes binding to the CCNURBS library shipped inside this package: one package per platform
(libccnurbs.so / ccnurbs.dll / libccnurbs.dylib, OpenBLAS beside it; see blender_manifest.toml).

Only the plan API is bound: ccn_plan_create (with the session's ccn_cache and, after an edit,
the plan it replaces, in its options) / ccn_plan_get_sizes, _get_stats / ccn_plan_evaluate (the first
evaluation after an edit: ccn_plan_evaluate_changed) / ccn_plan_destroy, and its face-varying channels and
per-vertex data (ccn_plan_add_fvar / ccn_plan_get_fvar_sizes / ccn_plan_evaluate_fvar /
ccn_plan_evaluate_vertex_data). Structures mirror csrc/include/ccnurbs.h field by field. Arrays are numpy
buffers passed by pointer; a failing call raises CCNError carrying the library's message.
"""
import ctypes
import os
import platform
import re
import sys

import numpy as np

LIB_NAME = {"win32": "ccnurbs.dll", "darwin": "libccnurbs.dylib"}.get(sys.platform, "libccnurbs.so")

c_int32_p = ctypes.POINTER(ctypes.c_int32)
c_double_p = ctypes.POINTER(ctypes.c_double)

# ccn_scheme, ccn_cap, ccn_corners (C enums: int)
SCHEMES = {"EIGEN": 0, "NURSS": 1, "CATMULL_CLARK": 2}
CAPS = {"GUIDED_BI5": 0, "REFINE": 1, "G1_FILL": 2}
CORNERS = {"ALL": 0, "PRESERVE_CORNERS": 1}
CREASE_METHODS = {"UNIFORM": 0, "CHAIKIN": 1}
# ccn_fvar_linear from Blender's UV Smooth (Subdivision Surface's names): OpenSubdiv's modes
FVAR_LINEAR = {"SMOOTH_ALL": 0, "PRESERVE_CORNERS": 1, "PRESERVE_CORNERS_AND_JUNCTIONS": 2,
               "PRESERVE_CORNERS_JUNCTIONS_AND_CONCAVE": 3, "PRESERVE_BOUNDARIES": 4, "NONE": 5}


# ccn_reason (ccnurbs.h), by name; the add-on's own failures have names of their own
# ("levels_refused", "linked_data")
REASONS = ("none", "other", "no_faces", "nonfinite_coordinate", "coordinate_range",
           "nan_sharpness", "face_too_few_vertices", "face_repeats_vertex", "index_out_of_range",
           "valence_limit", "face_size_limit", "out_of_memory")


class CCNError(Exception):
    """A library call failed. `status` is the ccn_status name, str(e) the library's message,
    `reason` a REASONS name (what the advice keys on), `element_verts` an edge's two vertices."""

    def __init__(self, status, message, element_kind=0, element=-1, reason="other",
                 element_verts=None):
        super().__init__(message)
        self.status = status
        self.element_kind = element_kind
        self.element = element
        self.reason = reason
        self.element_verts = element_verts


class ccn_error(ctypes.Structure):
    _fields_ = [("status", ctypes.c_int),
                ("element_kind", ctypes.c_int32),
                ("element", ctypes.c_int32),
                ("message", ctypes.c_char * 256),
                ("reason", ctypes.c_int32),
                ("element_verts", ctypes.c_int32 * 2)]


class ccn_cage(ctypes.Structure):
    _fields_ = [("num_verts", ctypes.c_int32),
                ("num_faces", ctypes.c_int32),
                ("num_edges", ctypes.c_int32),
                ("positions", c_double_p),
                ("face_sizes", c_int32_p),
                ("face_verts", c_int32_p),
                ("edge_verts", c_int32_p),
                ("edge_knots", c_double_p),
                ("edge_creases", c_double_p),
                ("vertex_creases", c_double_p)]


class ccn_options(ctypes.Structure):
    _fields_ = [("scheme", ctypes.c_int),
                ("cap", ctypes.c_int),
                ("levels", ctypes.c_int32),
                ("boundary_corners", ctypes.c_int32),
                ("threads", ctypes.c_int32),
                ("crease_method", ctypes.c_int32),
                ("ev_polyhedron", ctypes.c_int32),
                ("cache", ctypes.c_void_p),
                ("previous", ctypes.c_void_p)]


class ccn_sizes(ctypes.Structure):
    _fields_ = [("num_verts", ctypes.c_int32),
                ("num_faces", ctypes.c_int32),
                ("num_cage_verts", ctypes.c_int32),
                ("num_edges", ctypes.c_int32)]


class ccn_plan_stats(ctypes.Structure):
    _fields_ = [("levels", ctypes.c_int32),
                ("refine_levels", ctypes.c_int32),
                ("num_extraordinary", ctypes.c_int32),
                ("num_caps", ctypes.c_int32),
                ("num_cap_fallbacks", ctypes.c_int32),
                ("num_caps_deferred", ctypes.c_int32),
                ("num_ev_fallbacks", ctypes.c_int32),
                ("num_ev_verified", ctypes.c_int32),
                ("num_ev_outside_g1", ctypes.c_int32),
                ("num_ring_conflicts", ctypes.c_int32),
                ("num_ignored_verts", ctypes.c_int32),
                ("num_ignored_edges", ctypes.c_int32),
                ("num_sharp_edges", ctypes.c_int32),
                ("num_sharp_vertices", ctypes.c_int32),
                ("num_sharp_corners", ctypes.c_int32)]


class ccn_limit_mesh(ctypes.Structure):
    _fields_ = [("positions", c_double_p),
                ("normals", c_double_p),
                ("face_verts", c_int32_p),
                ("face_origin", c_int32_p),
                ("corner_normals", c_double_p),
                ("corner_edge_origin", c_int32_p),
                ("edge_verts", c_int32_p),
                ("corner_edges", c_int32_p),
                ("curvatures", c_double_p),       # NULL: not computed
                ("curvature_dirs", c_double_p)]


class ccn_fvar_channel(ctypes.Structure):
    _fields_ = [("width", ctypes.c_int32),
                ("num_values", ctypes.c_int32),
                ("values", c_double_p),
                ("indices", c_int32_p),
                ("linear", ctypes.c_int32)]


class ccn_fvar_sizes(ctypes.Structure):
    _fields_ = [("width", ctypes.c_int32),
                ("num_values", ctypes.c_int32),
                ("num_cage_values", ctypes.c_int32),
                ("num_seam_edges", ctypes.c_int32),
                ("num_sharp_values", ctypes.c_int32)]


_lib = None
_load_error = None
_dll_directory = None  # Windows: keeps the package folder on the DLL search path


def library_path():
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), LIB_NAME)


def platform_name():
    """This machine as Blender names extension platforms: linux-x64, windows-x64, macos-arm64..."""
    system = {"win32": "windows", "darwin": "macos"}.get(sys.platform, sys.platform)
    machine = platform.machine().lower()
    return "%s-%s" % (system, {"x86_64": "x64", "amd64": "x64", "aarch64": "arm64"}.get(machine,
                                                                                     machine))


def package_platforms():
    """The platforms this package was built for (its manifest's `platforms`), [] if unknown."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "blender_manifest.toml")
    try:
        with open(path, encoding="utf-8") as f:
            return next((re.findall(r'"([^"]+)"', ln) for ln in f if ln.startswith("platforms")), [])
    except OSError:
        return []


def _bind(lib):
    """Sets argtypes/restype once for every function used."""
    P = ctypes.c_void_p
    lib.ccn_plan_create.argtypes = [ctypes.POINTER(ccn_cage), ctypes.POINTER(ccn_options),
                                    ctypes.POINTER(P), ctypes.POINTER(ccn_error)]
    lib.ccn_plan_create.restype = ctypes.c_int
    lib.ccn_cache_create.argtypes = [ctypes.POINTER(P), ctypes.POINTER(ccn_error)]
    lib.ccn_cache_create.restype = ctypes.c_int
    lib.ccn_plan_get_sizes.argtypes = [P, ctypes.POINTER(ccn_sizes)]
    lib.ccn_plan_get_sizes.restype = ctypes.c_int
    lib.ccn_plan_get_stats.argtypes = [P, ctypes.POINTER(ccn_plan_stats)]
    lib.ccn_plan_get_stats.restype = ctypes.c_int
    lib.ccn_plan_get_evs.argtypes = [P, c_int32_p, c_int32_p, c_int32_p]
    lib.ccn_plan_get_evs.restype = ctypes.c_int
    lib.ccn_plan_evaluate.argtypes = [P, c_double_p, ctypes.POINTER(ccn_limit_mesh),
                                      ctypes.POINTER(ccn_error)]
    lib.ccn_plan_evaluate.restype = ctypes.c_int
    lib.ccn_plan_evaluate_changed.argtypes = lib.ccn_plan_evaluate.argtypes
    lib.ccn_plan_evaluate_changed.restype = ctypes.c_int
    lib.ccn_plan_destroy.argtypes = [P]
    lib.ccn_plan_destroy.restype = None
    lib.ccn_plan_add_fvar.argtypes = [P, ctypes.POINTER(ccn_fvar_channel), c_int32_p,
                                      ctypes.POINTER(ccn_error)]
    lib.ccn_plan_add_fvar.restype = ctypes.c_int
    lib.ccn_plan_get_fvar_sizes.argtypes = [P, ctypes.c_int32, ctypes.POINTER(ccn_fvar_sizes)]
    lib.ccn_plan_get_fvar_sizes.restype = ctypes.c_int
    lib.ccn_plan_evaluate_fvar.argtypes = [P, ctypes.c_int32, c_double_p, c_double_p, c_int32_p,
                                           ctypes.POINTER(ccn_error)]
    lib.ccn_plan_evaluate_fvar.restype = ctypes.c_int
    lib.ccn_plan_evaluate_vertex_data.argtypes = [P, ctypes.c_int32, c_double_p, c_double_p,
                                                  ctypes.POINTER(ccn_error)]
    lib.ccn_plan_evaluate_vertex_data.restype = ctypes.c_int
    lib.ccn_status_name.argtypes = [ctypes.c_int]
    lib.ccn_status_name.restype = ctypes.c_char_p


_operator_cache = [None]


def _cache(lib):
    """The session's ccn_cache: the guided bi-5 operator of each valence is built once and
    shared by every plan (a rebuild after an interval edit on a 32-gon cylinder: ~0.4 s -> a
    few ms). It lives as long as the loaded library (plans borrow from it, so it is never
    destroyed while one may exist); None (no sharing) if it cannot be made."""
    if _operator_cache[0] is None:
        handle, err = ctypes.c_void_p(), ccn_error()
        if lib.ccn_cache_create(ctypes.byref(handle), ctypes.byref(err)) != 0:
            return None
        _operator_cache[0] = handle
    return _operator_cache[0]


def load():
    """Returns the loaded library; raises CCNError('CCN_ERR_LOAD', ...) if it cannot be used."""
    global _lib, _load_error, _dll_directory
    if _lib is not None:
        return _lib
    if _load_error is not None:
        raise CCNError("CCN_ERR_LOAD", _load_error)
    path = library_path()
    here, built = platform_name(), package_platforms()
    wrong = ("this CCNURBS package is for %s, this Blender runs on %s: install the package made "
             "for %s" % (", ".join(built), here, here)) if built and here not in built else ""
    try:
        if not os.path.isfile(path):
            raise OSError("%s is not in the package" % LIB_NAME)
        if hasattr(os, "add_dll_directory") and _dll_directory is None:  # OpenBLAS beside it
            _dll_directory = os.add_dll_directory(os.path.dirname(path))
        lib = ctypes.CDLL(path)
        _bind(lib)
    except (OSError, AttributeError) as e:
        _load_error = "cannot load the CCNURBS library: %s%s" % (wrong + "; " if wrong else "", e)
        raise CCNError("CCN_ERR_LOAD", _load_error) from None
    _lib = lib
    return lib


def available():
    try:
        load()
        return True
    except CCNError:
        return False


def load_error():
    return _load_error


def status_name(status):
    try:
        name = load().ccn_status_name(status)
    except CCNError:
        name = None
    return name.decode("utf-8", "replace") if name else "CCN_STATUS_%d" % status


def _raise(status, err):
    msg = err.message.decode("utf-8", "replace").strip() or status_name(status)
    reason = REASONS[err.reason] if 0 <= err.reason < len(REASONS) else "other"
    verts = tuple(err.element_verts) if err.element_verts[0] >= 0 else None
    raise CCNError(status_name(status), msg, err.element_kind, err.element, reason, verts)


def _ptr(arr, ctype):
    return arr.ctypes.data_as(ctypes.POINTER(ctype)) if arr is not None else None


class Plan:
    """A ccn_plan: topology, knot intervals and options, evaluated for new positions.

    cage: positions (V,3), face_sizes (F,), face_verts (sum,), edge_verts (E,2) or None,
    edge_knots (E,) or None (<= 0, NaN, Inf: unset), edge_sharpness (E,) or None and
    vertex_sharpness (V,) or None (OpenSubdiv sharpness: ccn_cage.edge_creases / vertex_creases).
    options: scheme/cap/boundary/crease_method (enum identifiers), levels.
    previous: the open Plan this one replaces after an edit, given up (options.previous: where
    topology, creases and options are the same, e.g. an interval edit, its topology moves over
    and its unchanged stencils are reused; otherwise it is only freed). It is closed by the
    call, also when the call fails.
    """

    def __init__(self, positions, face_sizes, face_verts, edge_verts=None, edge_knots=None,
                 scheme="EIGEN", cap="GUIDED_BI5", boundary="ALL", levels=2, threads=0,
                 edge_sharpness=None, vertex_sharpness=None, crease_method="UNIFORM",
                 previous=None):
        lib = load()
        self._lib = lib
        self._handle = None
        self._buffers = None  # evaluate(topology=False)'s output arrays, reused
        self._curv = None  # evaluate(topology=False, curvature=True)'s curvatures, reused
        self._last = None  # the own arrays the last evaluate(topology=False) wrote, else None
        # an interval edit's plan starts from the output of the plan it replaces: its first
        # evaluate writes only what the edit changed (ccn_plan_evaluate_changed)
        self._inherit = previous._last if previous is not None else None
        self.changed_only = False  # the last evaluate was ccn_plan_evaluate_changed
        pos = np.ascontiguousarray(positions, dtype=np.float64).reshape(-1)
        fs = np.ascontiguousarray(face_sizes, dtype=np.int32).reshape(-1)
        fv = np.ascontiguousarray(face_verts, dtype=np.int32).reshape(-1)
        ev = ek = es = None
        if edge_verts is not None and len(edge_verts):
            ev = np.ascontiguousarray(edge_verts, dtype=np.int32).reshape(-1)
            for name, arr in (("edge_knots", edge_knots), ("edge_sharpness", edge_sharpness)):
                if arr is not None and np.size(arr) * 2 != ev.size:
                    raise CCNError("CCN_ERR_ARGUMENT", "%s has %d values for %d edges"
                                   % (name, np.size(arr), ev.size // 2))
            if edge_knots is not None:
                ek = np.ascontiguousarray(edge_knots, dtype=np.float64).reshape(-1)
            if edge_sharpness is not None:  # ccn_cage.edge_creases: OpenSubdiv sharpness
                es = np.ascontiguousarray(edge_sharpness, dtype=np.float64).reshape(-1)
        if pos.size % 3:
            raise CCNError("CCN_ERR_ARGUMENT", "positions must be 3 floats per vertex")
        vs = None
        if vertex_sharpness is not None:
            vs = np.ascontiguousarray(vertex_sharpness, dtype=np.float64).reshape(-1)
            if vs.size * 3 != pos.size:
                raise CCNError("CCN_ERR_ARGUMENT", "vertex_sharpness has %d values for %d vertices"
                               % (vs.size, pos.size // 3))
        self._keep = (pos, fs, fv, ev, ek, es, vs)  # the arrays must outlive plan creation
        cage = ccn_cage(num_verts=pos.size // 3, num_faces=fs.size,
                        num_edges=(ev.size // 2) if ev is not None else 0,
                        positions=_ptr(pos, ctypes.c_double), face_sizes=_ptr(fs, ctypes.c_int32),
                        face_verts=_ptr(fv, ctypes.c_int32), edge_verts=_ptr(ev, ctypes.c_int32),
                        edge_knots=_ptr(ek, ctypes.c_double),
                        edge_creases=_ptr(es, ctypes.c_double),
                        vertex_creases=_ptr(vs, ctypes.c_double))
        opts = ccn_options(scheme=SCHEMES[scheme], cap=CAPS[cap], levels=int(levels),
                           boundary_corners=CORNERS[boundary], threads=int(threads),
                           crease_method=CREASE_METHODS[crease_method])
        handle = ctypes.c_void_p()
        err = ccn_error()
        # the session's operators, and the plan this one replaces (consumed by the call,
        # whatever it returns)
        cache = _cache(lib)
        opts.cache = cache.value if cache is not None else None
        prev = previous._handle if previous is not None else None
        if prev is not None:
            previous._handle = None
            opts.previous = prev.value
        st = lib.ccn_plan_create(ctypes.byref(cage), ctypes.byref(opts), ctypes.byref(handle),
                                 ctypes.byref(err))
        if st != 0:
            _raise(st, err)
        self._handle = handle
        s, t = ccn_sizes(), ccn_plan_stats()
        st = lib.ccn_plan_get_sizes(handle, ctypes.byref(s)) or lib.ccn_plan_get_stats(handle, ctypes.byref(t))
        if st != 0:
            self.close()
            _raise(st, ccn_error())
        # buffer sizes and statistics in one dict (the panel shows both)
        self.sizes = {name: int(getattr(s, name)) for name, _ in ccn_sizes._fields_}
        self.sizes.update({name: int(getattr(t, name)) for name, _ in ccn_plan_stats._fields_})

    def evaluate(self, positions=None, topology=True, curvature=False):
        """Returns dict positions (N,3) f64, normals (N,3) f64, on creased surfaces
        corner_normals (F*4,3) f64 (each face corner's own side), and, if topology, face_verts
        (F,4) int32, face_origin (F,) int32, corner_edge_origin (F,4) int32 (the cage face
        corner whose edge each output corner's edge lies on, -1 inside a cage face), edge_verts
        (E,2) int32 and corner_edges (F,4) int32 (the output edges); with curvature,
        curvatures (N,2) f64: k1 >= k2, NaN where unbounded or not computed. Without
        topology the arrays are the plan's own, overwritten by the next such call."""
        if self._handle is None:
            raise CCNError("CCN_ERR_ARGUMENT", "plan was destroyed")
        n, f = self.sizes["num_verts"], self.sizes["num_faces"]
        inherit, self._inherit = self._inherit, None
        sharp = self.sizes.get("num_sharp_corners", 0) > 0
        if inherit is not None and (sorted(inherit) != sorted(["positions", "normals"] + (
                ["corner_normals"] if sharp else [])) or len(inherit["positions"]) != n):
            inherit = None  # not this output's arrays
        if inherit is not None:  # the earlier plan's output, kept where the edit changed nothing
            out = dict(inherit)
            if not topology:
                self._buffers = dict(inherit)
        elif topology or self._buffers is None:
            out = {"positions": np.empty((n, 3), np.float64),
                   "normals": np.empty((n, 3), np.float64)}
            if sharp:
                out["corner_normals"] = np.empty((4 * f, 3), np.float64)
            if not topology:  # position updates reuse these arrays (written before the next)
                self._buffers = out
        else:
            out = dict(self._buffers)
        if topology:
            out["face_verts"] = np.empty((f, 4), np.int32)
            out["face_origin"] = np.empty(f, np.int32)
            out["corner_edge_origin"] = np.empty((f, 4), np.int32)
            out["edge_verts"] = np.empty((self.sizes["num_edges"], 2), np.int32)
            out["corner_edges"] = np.empty((f, 4), np.int32)
        lm = ccn_limit_mesh(positions=_ptr(out["positions"], ctypes.c_double),
                            normals=_ptr(out["normals"], ctypes.c_double),
                            face_verts=_ptr(out.get("face_verts"), ctypes.c_int32),
                            face_origin=_ptr(out.get("face_origin"), ctypes.c_int32),
                            corner_normals=_ptr(out.get("corner_normals"), ctypes.c_double),
                            corner_edge_origin=_ptr(out.get("corner_edge_origin"), ctypes.c_int32),
                            edge_verts=_ptr(out.get("edge_verts"), ctypes.c_int32),
                            corner_edges=_ptr(out.get("corner_edges"), ctypes.c_int32))
        if curvature:  # position updates reuse the plan's array too (no fresh pages)
            kept = self._curv if not topology else None
            if kept is None or len(kept) != n:
                kept = np.empty((n, 2), np.float64)
                if not topology:
                    self._curv = kept
            out["curvatures"] = kept
            lm.curvatures = _ptr(kept, ctypes.c_double)
        pos = None
        if positions is not None:
            pos = np.ascontiguousarray(positions, dtype=np.float64).reshape(-1)
            if pos.size != 3 * self.sizes["num_cage_verts"]:
                raise CCNError("CCN_ERR_ARGUMENT", "expected %d cage positions, got %d"
                               % (self.sizes["num_cage_verts"], pos.size // 3))
        err = ccn_error()
        self._last = None
        self.changed_only = inherit is not None
        fn = self._lib.ccn_plan_evaluate_changed if inherit is not None else self._lib.ccn_plan_evaluate
        st = fn(self._handle, _ptr(pos, ctypes.c_double), ctypes.byref(lm), ctypes.byref(err))
        if st != 0:
            _raise(st, err)
        if not topology:  # the plan's own arrays (a caller keeps topology=True results)
            self._last = {k: out[k] for k in ("positions", "normals", "corner_normals") if k in out}
        return out

    EV_SURFACES = ("capped", "blended", "refined", "filled")  # ccn_ev_surface

    def evs(self):
        """The output's extraordinary points: (output vertex indices (K,) int32, how each is
        made (K,) int32: 0 capped, 1 cap blended, 2 refined limit, 3 G1 fill cap)."""
        if self._handle is None:
            raise CCNError("CCN_ERR_ARGUMENT", "plan was destroyed")
        n = ctypes.c_int32(0)
        st = self._lib.ccn_plan_get_evs(self._handle, ctypes.byref(n), None, None)
        idx = np.empty(n.value, np.int32)
        kind = np.empty(n.value, np.int32)
        if st == 0 and n.value:
            st = self._lib.ccn_plan_get_evs(self._handle, ctypes.byref(n), _ptr(idx, ctypes.c_int32),
                                            _ptr(kind, ctypes.c_int32))
        if st != 0:
            _raise(st, ccn_error())
        return idx, kind

    def add_fvar(self, values, indices, linear="PRESERVE_CORNERS"):
        """A face-varying channel: values (N, W), one value index per cage face corner (in
        face_verts order), linear = a UV Smooth identifier. Returns the channel index."""
        if self._handle is None:
            raise CCNError("CCN_ERR_ARGUMENT", "plan was destroyed")
        vals = np.ascontiguousarray(values, dtype=np.float64)
        vals = vals.reshape(len(vals), -1) if vals.ndim != 2 else vals
        idx = np.ascontiguousarray(indices, dtype=np.int32).reshape(-1)
        ch = ccn_fvar_channel(width=vals.shape[1], num_values=vals.shape[0],
                              values=_ptr(vals, ctypes.c_double), indices=_ptr(idx, ctypes.c_int32),
                              linear=FVAR_LINEAR[linear])
        out = ctypes.c_int32(-1)
        err = ccn_error()
        st = self._lib.ccn_plan_add_fvar(self._handle, ctypes.byref(ch), ctypes.byref(out),
                                         ctypes.byref(err))
        if st != 0:
            _raise(st, err)
        return out.value

    def fvar_sizes(self, channel):
        s = ccn_fvar_sizes()
        st = self._lib.ccn_plan_get_fvar_sizes(self._handle, channel, ctypes.byref(s))
        if st != 0:
            _raise(st, ccn_error())
        return {name: int(getattr(s, name)) for name, _ in ccn_fvar_sizes._fields_}

    def evaluate_fvar(self, channel, values=None):
        """Limit values of a channel for new values (N, W) of its cage values (None: those
        given): (values (M, W) f64, face_values (F, 4) int32 per output face corner)."""
        z = self.fvar_sizes(channel)
        out = np.empty((z["num_values"], z["width"]), np.float64)
        fv = np.empty((self.sizes["num_faces"], 4), np.int32)
        v = None
        if values is not None:
            v = np.ascontiguousarray(values, dtype=np.float64).reshape(-1)
            if v.size != z["width"] * z["num_cage_values"]:
                raise CCNError("CCN_ERR_ARGUMENT", "expected %d values of width %d"
                               % (z["num_cage_values"], z["width"]))
        err = ccn_error()
        st = self._lib.ccn_plan_evaluate_fvar(self._handle, channel, _ptr(v, ctypes.c_double),
                                              _ptr(out, ctypes.c_double), _ptr(fv, ctypes.c_int32),
                                              ctypes.byref(err))
        if st != 0:
            _raise(st, err)
        return out, fv

    def evaluate_vertex_data(self, data):
        """Per-vertex data (cage vertices, W) interpolated like the positions: (output
        vertices, W) f64."""
        d = np.ascontiguousarray(data, dtype=np.float64)
        d = d.reshape(self.sizes["num_cage_verts"], -1)
        out = np.empty((self.sizes["num_verts"], d.shape[1]), np.float64)
        err = ccn_error()
        st = self._lib.ccn_plan_evaluate_vertex_data(self._handle, d.shape[1],
                                                     _ptr(d, ctypes.c_double),
                                                     _ptr(out, ctypes.c_double), ctypes.byref(err))
        if st != 0:
            _raise(st, err)
        return out

    def close(self):
        if self._handle is not None:
            self._lib.ccn_plan_destroy(self._handle)
            self._handle = None

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass
