"""The preview PNG, rendered off-screen with VTK: a shaded, depth-correct view and plane sections.

VTK comes with OCP (the ``cadquery-ocp`` package); the preview imports only the VTK modules it draws with (the ``rjcad`` program
renders while its CAD process builds, and has not loaded all of VTK). The window is off-screen: EGL (Mesa's
software rasteriser when there is no GPU) unless ``VTK_DEFAULT_OPENGL_WINDOW`` says otherwise, so no display
is needed. One window holds every panel (a viewport each): the isometric view (bodies in their colours, the
tendon as a red tube, dashed on an overlay where a body hides it), then each section (label, point, normal)
as the bodies' cut outlines seen along the normal, the tendon dashed. Units: mm in, pixels out.
"""

from __future__ import annotations

import functools
import math
import os

import numpy as np

#: Body colours when the caller gives none, in order.
PALETTE = ("#9aa5b1", "#3b82c4", "#e0a33a", "#6aa84f", "#b45f9e", "#cc4125", "#45818e")
TENDON = "#d62728"
#: One panel's size [px]; the figure is 2 panels wide when there are sections.
PANEL = (700, 550)
TITLE_PX = 40


def rgb(colour: str) -> tuple[float, float, float]:
    """'#rrggbb' → (r, g, b) in [0, 1]."""
    c = colour.lstrip("#")
    r, g, b = (int(c[i : i + 2], 16) / 255.0 for i in (0, 2, 4))
    return r, g, b


@functools.cache
def _vtk():
    """The VTK modules the preview uses (imported on first use; registers the OpenGL and font back ends)."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import vtkmodules.vtkRenderingFreeType
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the render window's implementation)
    from vtkmodules import vtkCommonCore, vtkCommonDataModel, vtkFiltersCore, vtkIOImage, vtkRenderingCore
    from vtkmodules.util import numpy_support

    # text drawn by FreeType always: VTK gives a label with '|' to matplotlib's MathText when it can (when the
    # process has loaded all of VTK), which draws it differently
    vtkRenderingCore.vtkTextRenderer.GetInstance().SetDefaultBackend(vtkRenderingCore.vtkTextRenderer.FreeType)

    class V:
        np = numpy_support

    for mod in (vtkCommonCore, vtkCommonDataModel, vtkFiltersCore, vtkIOImage, vtkRenderingCore):
        for name in dir(mod):
            if name.startswith("vtk"):
                setattr(V, name, getattr(mod, name))
    return V


def warm_up() -> None:
    """Start the off-screen renderer (EGL display, OpenGL context): about 0.1 s that the first preview
    would otherwise pay; ``mesh_export.prepare`` runs it while the CAD process builds."""
    V = _vtk()
    win = V.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(8, 8)
    win.SetMultiSamples(0)
    win.AddRenderer(V.vtkRenderer())
    win.Render()
    win.Finalize()


def _cells(V, conn: np.ndarray, per_cell: int):
    """A vtkCellArray of cells of ``per_cell`` points from a (n, per_cell) index array."""
    conn = np.ascontiguousarray(conn, dtype=np.int64)
    offsets = np.arange(0, conn.size + 1, per_cell, dtype=np.int64)
    cells = V.vtkCellArray()
    cells.SetData(
        V.np.numpy_to_vtkIdTypeArray(offsets, deep=True), V.np.numpy_to_vtkIdTypeArray(conn.ravel(), deep=True)
    )
    return cells


def polydata(V, points: np.ndarray, faces: np.ndarray | None = None, lines: np.ndarray | None = None):
    """vtkPolyData of ``points`` [mm] with triangles ``faces`` or segments ``lines`` (index arrays)."""
    pd = V.vtkPolyData()
    pts = V.vtkPoints()
    pts.SetData(V.np.numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True))
    pd.SetPoints(pts)
    if faces is not None:
        pd.SetPolys(_cells(V, faces, 3))
    if lines is not None:
        pd.SetLines(_cells(V, lines, 2))
    return pd


def _actor(V, source, colour: str, *, width: float = 0.0, port=None, diffuse: float = 0.8):
    """An actor of polydata ``source`` (or of a filter's ``port``) in ``colour``; ``width``: line width [px]."""
    mapper = V.vtkPolyDataMapper()
    if port is not None:
        mapper.SetInputConnection(port)
    else:
        mapper.SetInputData(source)
    mapper.ScalarVisibilityOff()
    actor = V.vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.SetColor(*rgb(colour))
    prop.SetAmbient(0.25)
    prop.SetDiffuse(diffuse)
    prop.SetSpecular(0.15)
    if width:  # an unlit line in its exact colour
        prop.SetLineWidth(width)
        prop.LightingOff()
        prop.SetAmbient(0.0)
        prop.SetDiffuse(1.0)
        prop.SetSpecular(0.0)
    return actor


def _text(V, text: str, size: int, colour=(0.1, 0.1, 0.1), *, x: float = 0.5, y: float = 0.97, bold=False):
    """A text actor at (x, y) in its viewport's normalised coordinates (centred on x, top at y)."""
    t = V.vtkTextActor()
    t.SetInput(text)
    p = t.GetTextProperty()
    p.SetFontSize(size)
    p.SetColor(*colour)
    p.SetBold(bold)
    p.SetJustificationToCentered() if x == 0.5 else p.SetJustificationToLeft()
    p.SetVerticalJustificationToTop()
    t.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
    t.SetPosition(x, y)
    return t


def _tube(V, pts: np.ndarray, radius: float):
    """A red tube along the polyline ``pts`` [mm] (the tendon)."""
    seg = np.column_stack([np.arange(len(pts) - 1), np.arange(1, len(pts))])
    tube = V.vtkTubeFilter()
    tube.SetInputData(polydata(V, pts, lines=seg))
    tube.SetRadius(radius)
    tube.SetNumberOfSides(12)
    tube.CappingOn()
    return _actor(V, None, TENDON, port=tube.GetOutputPort())


def iso_panel(V, ren, meshes: dict, colours: dict[str, str], lines, span: float) -> None:
    """Shaded bodies and the tendon tube, seen from azimuth -60°, elevation 28° (orthographic)."""
    for name, m in meshes.items():
        ren.AddActor(_actor(V, polydata(V, m.vertices, faces=m.faces), colours[name]))
    for pts in lines:
        ren.AddActor(_tube(V, np.asarray(pts, dtype=float), max(0.35, span / 250)))
    az, el = math.radians(-60.0), math.radians(28.0)
    cam = ren.GetActiveCamera()
    cam.SetFocalPoint(0, 0, 0)
    cam.SetPosition(math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
    cam.SetViewUp(0, 0, 1)
    cam.ParallelProjectionOn()
    ren.ResetCamera()
    cam.SetParallelScale(cam.GetParallelScale() * 0.8)
    light = V.vtkLight()
    light.SetLightTypeToCameraLight()
    light.SetPosition(0.4, 0.6, 1.0)
    light.SetIntensity(0.9)
    ren.AddLight(light)


def section_panel(V, ren, meshes: dict, colours: dict[str, str], lines, origin, normal, bounds) -> None:
    """The bodies' outlines cut by the plane (``origin``, ``normal``), seen along the normal; tendon dashed."""
    import trimesh

    nrm = np.asarray(normal, dtype=float)
    org = np.asarray(origin, dtype=float)
    for name, m in meshes.items():
        segs = trimesh.intersections.mesh_plane(m, nrm, org)
        if len(segs):
            pts = segs.reshape(-1, 3)
            ren.AddActor(
                _actor(V, polydata(V, pts, lines=np.arange(len(pts)).reshape(-1, 2)), colours[name], width=1.5)
            )
    for pts in lines:
        pts = np.asarray(pts, dtype=float)
        pts = pts - np.outer((pts - org) @ nrm, nrm) + nrm * 0.01  # onto the plane, just in front
        dense = _dashes(pts, max(0.5, float(np.ptp(bounds, axis=0).max()) / 120))
        ren.AddActor(_actor(V, polydata(V, dense, lines=np.arange(len(dense)).reshape(-1, 2)), TENDON, width=1.5))
    _look_along(ren.GetActiveCamera(), nrm, org, bounds)
    ren.ResetCameraClippingRange()


def _look_along(cam, nrm: np.ndarray, org: np.ndarray, bounds: np.ndarray) -> None:
    """Orthographic camera onto the section plane, +X (or +Y) to the right, framing the bodies' extent."""
    up = np.array([0.0, 1.0, 0.0]) if abs(nrm[2]) > 0.5 else np.array([0.0, 0.0, 1.0])
    side = -1.0 if abs(nrm[1]) > 0.5 else 1.0  # a y-section seen from -Y keeps +X to the right
    right = np.cross(-side * nrm, up)
    lo, hi = bounds
    centre = (lo + hi) / 2
    centre = centre - ((centre - org) @ nrm) * nrm
    span = float(np.ptp(bounds, axis=0).max()) + 10
    cam.SetFocalPoint(*centre)
    cam.SetPosition(*(centre + side * nrm * span))
    cam.SetViewUp(*up)
    cam.ParallelProjectionOn()
    half_w, half_h = np.abs(right) @ (hi - lo) / 2, up @ (hi - lo) / 2
    cam.SetParallelScale(1.12 * max(half_h, half_w * PANEL[1] / PANEL[0]) + 1.0)
    cam.SetClippingRange(0.1, 2 * span)


def _dashes(pts: np.ndarray, dash: float) -> np.ndarray:
    """Start and end points of dashes of length ``dash`` [mm] (gaps as long) along the polyline ``pts``."""
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    starts = np.arange(0.0, s[-1], 2 * dash)
    ends = np.minimum(starts + dash, s[-1])
    at = np.column_stack([starts, ends]).ravel()
    return np.column_stack([np.interp(at, s, pts[:, k]) for k in range(3)])


def preview_png(meshes: dict, title: str, lines=(), colours: dict[str, str] | None = None, sections=()) -> bytes:
    """PNG bytes of the preview: the isometric view and the ``sections`` (label, origin, normal)."""
    V = _vtk()
    colours = {n: (colours or {}).get(n, PALETTE[i % len(PALETTE)]) for i, n in enumerate(meshes)}
    allv = np.vstack([m.vertices for m in meshes.values()])
    bounds = np.array([allv.min(axis=0), allv.max(axis=0)])
    n = 1 + len(sections)
    cols = 2 if n > 1 else 1
    rows = math.ceil(n / cols)
    w, h = PANEL[0] * cols, PANEL[1] * rows + TITLE_PX
    win = V.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(w, h)
    win.SetMultiSamples(0)  # anti-aliasing triples the time on a software rasteriser
    win.SetNumberOfLayers(2)
    top = 1.0 - TITLE_PX / h
    head = V.vtkRenderer()
    head.SetViewport(0, top, 1, 1)
    head.SetBackground(1, 1, 1)
    head.AddViewProp(_text(V, title, 17, y=0.85))
    win.AddRenderer(head)
    for k in range(n):
        r, c = divmod(k, cols)
        ren = V.vtkRenderer()
        ren.SetViewport(c / cols, top * (1 - (r + 1) / rows), (c + 1) / cols, top * (1 - r / rows))
        ren.SetBackground(*((0.97, 0.97, 0.98) if k else (1, 1, 1)))
        if k == 0:
            iso_panel(V, ren, meshes, colours, lines, float(np.ptp(bounds, axis=0).max()))
            _legend(V, ren, colours, bool(lines))
            win.AddRenderer(_hidden_tendon(V, ren, lines, float(np.ptp(bounds, axis=0).max())))
        else:
            label, origin, normal = sections[k - 1]
            section_panel(V, ren, meshes, colours, lines, origin, normal, bounds)
            ren.AddViewProp(_text(V, label, 13))
        win.AddRenderer(ren)
    return _png(V, win)


def _hidden_tendon(V, ren, lines, span: float):
    """An overlay (layer 1, same camera and viewport) drawing the tendon dashed where the bodies hide it."""
    over = V.vtkRenderer()
    over.SetLayer(1)
    over.SetViewport(*ren.GetViewport())
    over.SetActiveCamera(ren.GetActiveCamera())
    over.InteractiveOff()
    for pts in lines:
        dense = _dashes(np.asarray(pts, dtype=float), max(0.5, span / 120))
        a = _actor(V, polydata(V, dense, lines=np.arange(len(dense)).reshape(-1, 2)), TENDON, width=1.5)
        a.GetProperty().SetOpacity(0.8)
        over.AddActor(a)
    return over


def _legend(V, ren, colours: dict[str, str], tendon: bool) -> None:
    """Body names in their colours (and 'tendon' in red), top left of the isometric panel."""
    entries = list(colours.items()) + ([("tendon", TENDON)] if tendon else [])
    for i, (name, colour) in enumerate(entries):
        ren.AddViewProp(_text(V, name, 14, rgb(colour), x=0.02, y=0.97 - 0.045 * i, bold=True))
    ren.AddViewProp(_text(V, "isometric", 14, y=0.97))


def _png(V, win) -> bytes:
    """Render ``win`` and return its pixels as PNG bytes."""
    win.Render()
    grab = V.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    grab.ShouldRerenderOff()
    grab.Update()
    writer = V.vtkPNGWriter()
    writer.WriteToMemoryOn()
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    data = V.np.vtk_to_numpy(writer.GetResult()).tobytes()
    win.Finalize()
    return data
