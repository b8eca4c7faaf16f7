"""Pictures of a CoReDEM run: the particles as spheres at their radius, coloured by a field, over
a slice of a gas field at the same instant. Run by `coredem render` with ParaView's pvbatch
(docs/orchestrator.md "Pictures"); it can also be run directly:

    pvbatch render_run.py RUN_DIR [--times T,T,...] [--field NAME] [--gas-field NAME]
                                  [--out DIR] [--size W,H] [--slice F] [--particles all|none]
                                  [--particle-opacity A] [--particle-scale S]

RUN_DIR/outputs.csv lists the synchronized outputs (step, time_s, particles, gas); each chosen
time gives DIR/<field>_<step>.png (DIR defaults to RUN_DIR/render). With more than one time,
DIR/<field>.mp4 is made when ffmpeg is on PATH, else DIR/<field>.gif when Pillow is importable.

--field: a particle array (temperature, velocity, diameter, species_<name>, ...; vectors are
coloured by magnitude; default temperature when it varies, else velocity). --gas-field: an
OpenFOAM field of the gas folder (default alphac when present, else U, else p), or p_Pa: the
pressure in Pa (coredemFoam's constant-property gas writes the kinematic p = p/rho_g in m^2/s^2;
p_Pa is rho_g * p from case.yaml's gas_properties.density; the ideal gas's p is already in Pa). --times: decimal
times in seconds (the nearest output of each is drawn), default every output.

Every picture carries its time stamp (t and step), a colour legend for the particles and one for
the gas slice, and a scale bar (a ruler of a round length in mm under the domain). --slice: where
the gas slice cuts the viewing axis, as a fraction of the domain's depth (0 front .. 1 back;
default 0.5). In a bed one cell deep the particles hide the slice: --particles none draws the gas
alone, --particle-opacity (0..1) makes them see-through, --particle-scale (0..1) shrinks them.
"""
import argparse
import csv
import math
import os
import shutil
import subprocess
import sys

from paraview.simple import (Calculator, ColorBy, CreateView, GetColorTransferFunction, GetScalarBar,
                             GetDisplayProperties, Glyph, OpenFOAMReader, Render, Ruler,
                             SaveScreenshot, Show, Slice, Text, UpdatePipeline, XDMFReader)
from paraview import servermanager as sm


def parse_args():
    ap = argparse.ArgumentParser(description="Render a CoReDEM run folder with ParaView")
    ap.add_argument("run_dir")
    ap.add_argument("--times", default="", help="comma-separated times in s (default: all)")
    ap.add_argument("--field", default="", help="particle array to colour by")
    ap.add_argument("--gas-field", default="", help="gas field of the slice")
    ap.add_argument("--out", default="", help="output folder (default RUN_DIR/render)")
    ap.add_argument("--size", default="", help="image size W,H in pixels (default: fit)")
    ap.add_argument("--slice", type=float, default=0.5,
                    help="slice position along the viewing axis, fraction of the depth (0..1)")
    ap.add_argument("--particles", choices=("all", "none"), default="all",
                    help="draw the particles (all) or the gas slice alone (none)")
    ap.add_argument("--particle-opacity", type=float, default=1.0,
                    help="particle opacity 0..1 (see the gas slice through them)")
    ap.add_argument("--particle-scale", type=float, default=1.0,
                    help="sphere diameter as a fraction of the particle diameter (0..1]")
    a = ap.parse_args()
    if not 0.0 <= a.slice <= 1.0:
        ap.error(f"--slice {a.slice}: give a fraction of the domain depth between 0 and 1")
    if not 0.0 <= a.particle_opacity <= 1.0:
        ap.error(f"--particle-opacity {a.particle_opacity}: give a value between 0 and 1")
    if not 0.0 < a.particle_scale <= 1.0:
        ap.error(f"--particle-scale {a.particle_scale}: give a value in (0, 1]")
    return a


def nice_length(span):
    """A round length (1, 2 or 5 times a power of ten) of about a fifth of span."""
    target = max(span, 1e-30) / 5.0
    p = 10.0 ** math.floor(math.log10(target))
    for m in (5.0, 2.0, 1.0):
        if m * p <= target:
            return m * p
    return p


def set_location(prop, where, old):
    """WindowLocation names changed between ParaView versions ('Upper Center' / 'UpperCenter')."""
    try:
        prop.WindowLocation = where
    except (ValueError, AttributeError):
        prop.WindowLocation = old


def read_outputs(run_dir):
    path = os.path.join(run_dir, "outputs.csv")
    if not os.path.exists(path):
        sys.exit(f"{path} not found: the run wrote no synchronized outputs (set output.every or "
                 "output.every_seconds in case.yaml)")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no outputs listed")
    return rows


def choose(rows, times):
    if not times:
        return rows
    chosen = []
    for t in times:
        best = min(rows, key=lambda r: abs(float(r["time_s"]) - t))
        if best not in chosen:
            chosen.append(best)
    return chosen


def gravity_axis(run_dir):
    """The vertical axis (largest gravity component in the run's case.yaml; y when unknown)."""
    try:
        import yaml

        with open(os.path.join(run_dir, "case.yaml")) as f:
            g = (yaml.safe_load(f) or {}).get("gravity", [0.0, -9.81, 0.0])
        return max(range(3), key=lambda i: abs(float(g[i])))
    except Exception:  # no case file or no PyYAML
        return 1


def pressure_factor(run_dir):
    """(factor, note): p_Pa = factor * p. coredemFoam's constant-property gas solves the kinematic
    pressure p/rho_g (m^2/s^2), its ideal gas p in Pa (docs/coredemFoam.md)."""
    try:
        import yaml

        with open(os.path.join(run_dir, "case.yaml")) as f:
            gp = (yaml.safe_load(f) or {}).get("gas_properties") or {}
    except Exception:  # no case file or no PyYAML: the documented default (constant, air)
        gp = {}
    if gp.get("model", "constant") == "ideal_gas":
        return 1.0, "p is in Pa (ideal gas)"
    rho = float(gp.get("density", 1.204))
    return rho, f"p is kinematic (m^2/s^2): p_Pa = {rho:g} kg/m^3 * p"


def array_info(proxy, name):
    """(number of components, range) of a point array, or None when absent."""
    info = proxy.GetDataInformation().GetPointDataInformation().GetArrayInformation(name)
    if info is None:
        return None
    comps = info.GetNumberOfComponents()
    return comps, info.GetComponentRange(-1 if comps > 1 else 0)


def cell_array_info(proxy, name):
    info = proxy.GetDataInformation().GetCellDataInformation().GetArrayInformation(name)
    if info is None:
        return None
    comps = info.GetNumberOfComponents()
    return comps, info.GetComponentRange(-1 if comps > 1 else 0)


def main():
    a = parse_args()
    run_dir = os.path.abspath(a.run_dir)
    rows = read_outputs(run_dir)
    times = [float(t) for t in a.times.split(",") if t.strip()]
    rows = choose(rows, times)
    out = os.path.abspath(a.out or os.path.join(run_dir, "render"))
    os.makedirs(out, exist_ok=True)
    width, height = (int(v) for v in (a.size or "1000,800").split(","))

    # Particles: the XDMF index of the snapshots, spheres at their radius.
    particles = XDMFReader(FileNames=[os.path.join(run_dir, "particles.xdmf")])
    particles.UpdatePipelineInformation()
    t0 = float(rows[0]["time_s"])
    UpdatePipeline(time=t0, proxy=particles)
    field = a.field
    if not field:
        temp = array_info(particles, "temperature")
        field = "temperature" if temp and temp[1][1] - temp[1][0] > 1e-9 else "velocity"
    if array_info(particles, field) is None:
        names = [particles.PointData.GetArray(i).GetName()
                 for i in range(particles.PointData.GetNumberOfArrays())]
        sys.exit(f"no particle array '{field}'; the snapshots have: {', '.join(sorted(names))}")
    spheres = Glyph(Input=particles, GlyphType="Sphere")
    spheres.ScaleArray = ["POINTS", "diameter" if array_info(particles, "diameter") else "radius"]
    spheres.ScaleFactor = (1.0 if array_info(particles, "diameter") else 2.0) * a.particle_scale
    spheres.GlyphMode = "All Points"
    spheres.GlyphType.Radius = 0.5
    spheres.GlyphType.ThetaResolution = 12
    spheres.GlyphType.PhiResolution = 12

    # Gas: the CFD participant's folder (OpenFOAM reader), sliced through the middle.
    gas_dirs = [r["gas"] for r in rows if r.get("gas")]
    gas = None
    if gas_dirs:
        case_dir = os.path.join(run_dir, os.path.dirname(gas_dirs[0]))
        # A decomposed run (cfd.ranks > 1) lists processor0's time folders: the reader assembles
        # every processor's fields from the case folder above (no reconstructPar).
        decomposed = os.path.basename(case_dir).startswith("processor")
        if decomposed:
            case_dir = os.path.dirname(case_dir)
        foam = os.path.join(case_dir, "case.foam")
        if not os.path.exists(foam):
            open(foam, "w").close()
        gas = OpenFOAMReader(FileName=foam)
        if decomposed:
            gas.CaseType = "Decomposed Case"
        gas.MeshRegions = ["internalMesh"]
        gas.UpdatePipelineInformation()
        UpdatePipeline(time=t0, proxy=gas)
        if a.gas_field == "p_Pa" and cell_array_info(gas, "p_Pa") is None:
            factor, note = pressure_factor(run_dir)
            gas = Calculator(Input=gas)
            gas.AttributeType = "Cell Data"
            gas.ResultArrayName = "p_Pa"
            gas.Function = f"p*{factor!r}"
            UpdatePipeline(time=t0, proxy=gas)
            print(f"p_Pa: {note}", flush=True)

    up = gravity_axis(run_dir)
    bounds = particles.GetDataInformation().GetBounds()
    if gas is not None:
        bounds = gas.GetDataInformation().GetBounds()
    extent = [bounds[2 * i + 1] - bounds[2 * i] for i in range(3)]
    # Look along the thinnest horizontal axis (a quasi-2D bed is seen face on).
    depth = min((i for i in range(3) if i != up), key=lambda i: extent[i])
    centre = [0.5 * (bounds[2 * i] + bounds[2 * i + 1]) for i in range(3)]

    if not a.size:  # the domain's aspect ratio plus room for the two colour bars
        across = [i for i in range(3) if i not in (up, depth)][0]
        height = 800
        width = int(min(2400, max(700, height * extent[across] / max(extent[up], 1e-30) + 500)))
    view = CreateView("RenderView")
    view.ViewSize = [width, height]
    view.OrientationAxesVisibility = 0
    view.Background = [1.0, 1.0, 1.0]
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass

    gas_field = a.gas_field
    if gas is not None:
        cut = Slice(Input=gas)
        cut.SliceType = "Plane"
        normal = [0.0, 0.0, 0.0]
        normal[depth] = 1.0
        origin = list(centre)
        # --slice: 0 the front face (towards the camera), 1 the back face
        origin[depth] = bounds[2 * depth + 1] - a.slice * extent[depth]
        cut.SliceType.Origin = origin
        cut.SliceType.Normal = normal
        UpdatePipeline(time=t0, proxy=cut)
        if not gas_field:
            for cand in ("alphac", "U", "p"):
                if cell_array_info(cut, cand):
                    gas_field = cand
                    break
        if gas_field and cell_array_info(cut, gas_field) is None:
            sys.exit(f"no gas field '{gas_field}' in {os.path.dirname(foam)}")
        cut_display = Show(cut, view)
        # Drawn behind every particle: the slice's display moves to the back of the domain.
        shift = [0.0, 0.0, 0.0]
        shift[depth] = -(origin[depth] - bounds[2 * depth] + 0.01 * max(extent))
        cut_display.Position = shift
        if gas_field:
            ColorBy(cut_display, ("CELLS", gas_field, "Magnitude"))
            lut = GetColorTransferFunction(gas_field)
            lut.ApplyPreset("Cool to Warm", True)
            bar = GetScalarBar(lut, view)
            bar.Title = f"gas {gas_field}" + (" [m2/s2, kinematic]" if gas_field == "p" and
                                               pressure_factor(run_dir)[0] != 1.0 else "")
            bar.ComponentTitle = ""
            bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
            bar.WindowLocation = "Any Location"
            bar.Position = [0.02, 0.1]
            cut_display.SetScalarBarVisibility(view, True)

    sphere_display = Show(spheres, view)
    sphere_display.Visibility = 1 if a.particles == "all" else 0
    sphere_display.Opacity = a.particle_opacity
    ColorBy(sphere_display, ("POINTS", field, "Magnitude"))
    plut = GetColorTransferFunction(field)
    plut.ApplyPreset("Inferno (matplotlib)", True)
    pbar = GetScalarBar(plut, view)
    pbar.Title = f"particles {field}"
    pbar.ComponentTitle = "magnitude" if (array_info(particles, field) or (1,))[0] > 1 else ""
    pbar.TitleColor = pbar.LabelColor = [0.0, 0.0, 0.0]
    pbar.WindowLocation = "Any Location"
    pbar.Position = [0.76, 0.1]
    sphere_display.SetScalarBarVisibility(view, a.particles == "all")

    # Time stamp (updated per picture) and a scale bar: a ruler of a round length under the domain.
    stamp = Text(Text="")
    stamp_display = Show(stamp, view)
    stamp_display.Color = [0.0, 0.0, 0.0]
    stamp_display.FontSize = 14
    set_location(stamp_display, "Upper Center", "UpperCenter")
    across = [i for i in range(3) if i not in (up, depth)][0]
    length = nice_length(extent[across])
    p1 = [bounds[0], bounds[2], bounds[4]]
    p1[depth] = bounds[2 * depth + 1]  # the front face: never behind the particles
    p1[up] = bounds[2 * up] - 0.04 * extent[up]
    p2 = list(p1)
    p2[across] += length
    ruler = Ruler(Point1=p1, Point2=p2)
    ruler_display = Show(ruler, view)
    for prop, value in (("AxisColor", [0.0, 0.0, 0.0]), ("Color", [0.0, 0.0, 0.0]),
                        ("Scale", 1000.0), ("LabelFormat", "%-#.3g mm"), ("NumberOfTicks", 2)):
        try:  # the label in mm (Scale 1000), not the default metres; names vary by version
            setattr(ruler_display, prop, value)
        except (AttributeError, ValueError):
            pass
    print(f"scale bar: {length * 1e3:g} mm; slice at {a.slice:g} of the depth; particles "
          f"{a.particles} (opacity {a.particle_opacity:g}, scale {a.particle_scale:g})", flush=True)

    # Camera: along the depth axis, the vertical axis up, the whole domain in view.
    view.CameraFocalPoint = centre
    position = list(centre)
    position[depth] += 4.0 * max(extent)
    view.CameraPosition = position
    upv = [0.0, 0.0, 0.0]
    upv[up] = 1.0
    view.CameraViewUp = upv
    view.CameraParallelProjection = 1
    view.ResetCamera()

    pngs = []
    for r in rows:
        t = float(r["time_s"])
        view.ViewTime = t
        UpdatePipeline(time=t, proxy=spheres)
        rng = array_info(spheres, field)
        if rng:
            lo, hi = rng[1]
            if not math.isfinite(lo) or hi - lo <= 1e-12 * max(1.0, abs(hi)):
                lo, hi = lo - 1.0, hi + 1.0
            plut.RescaleTransferFunction(lo, hi)
        if gas is not None and gas_field:
            UpdatePipeline(time=t, proxy=cut)
            g = cell_array_info(cut, gas_field)
            if g:
                glo, ghi = g[1]
                if ghi - glo <= 1e-12 * max(1.0, abs(ghi)):
                    glo, ghi = glo - 1.0, ghi + 1.0
                GetColorTransferFunction(gas_field).RescaleTransferFunction(glo, ghi)
        stamp.Text = f"t = {t:.6g} s   (step {int(r['step'])})"
        view.ResetCamera()
        Render(view)
        png = os.path.join(out, f"{field}_{int(r['step']):08d}.png")
        SaveScreenshot(png, view, ImageResolution=[width, height])
        pngs.append(png)
        print(f"t = {t:.9g} s (step {r['step']}): {png}", flush=True)

    if len(pngs) > 1:
        animate(pngs, out, field)


def animate(pngs, out, field):
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg:
        listing = os.path.join(out, f"{field}.frames.txt")
        with open(listing, "w") as f:
            for p in pngs:
                f.write(f"file '{p}'\nduration 0.25\n")
        movie = os.path.join(out, f"{field}.mp4")
        subprocess.run([ffmpeg, "-y", "-loglevel", "error", "-f", "concat", "-safe", "0", "-i",
                        listing, "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p",
                        movie], check=True)
        os.remove(listing)
        print(f"animation: {movie}")
        return
    try:
        from PIL import Image
    except ImportError:
        print("no animation: neither ffmpeg nor Pillow found", flush=True)
        return
    frames = [Image.open(p).convert("P", palette=Image.ADAPTIVE) for p in pngs]
    gif = os.path.join(out, f"{field}.gif")
    frames[0].save(gif, save_all=True, append_images=frames[1:], duration=250, loop=0)
    print(f"animation: {gif} (ffmpeg not found: GIF made with Pillow)")


if __name__ == "__main__":
    main()
