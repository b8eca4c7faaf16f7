"""pvbatch check of a run's particles.xdmf (tests/e2e/paraview): ParaView's XDMF reader loads the
last snapshot and every named array it shows must equal the snapshot .h5's data.

Usage: pvbatch check_xdmf.py RUN_DIR ARRAY [ARRAY ...]
  ARRAY: a node array name as the XDMF names it (e.g. species_Fe2O3, velocity, temperature).
Prints one line per array and exits 1 on the first mismatch (relative 1e-12).
"""
import csv
import os
import sys

import h5py
import numpy as np
from paraview import servermanager as sm
from paraview.simple import XDMFReader, UpdatePipeline
from vtk.numpy_interface import dataset_adapter as dsa

run_dir, names = sys.argv[1], sys.argv[2:]
with open(os.path.join(run_dir, "outputs.csv"), newline="") as f:
    rows = list(csv.DictReader(f))
last = rows[-1]
t = float(last["time_s"])
reader = XDMFReader(FileNames=[os.path.join(run_dir, "particles.xdmf")])
reader.UpdatePipelineInformation()
UpdatePipeline(time=t, proxy=reader)
data = dsa.WrapDataObject(sm.Fetch(reader))
points = np.asarray(data.Points)

with h5py.File(os.path.join(run_dir, last["particles"]), "r") as h5:
    position = h5["/particles/position"][()]
    if not np.allclose(points, position, rtol=1e-12, atol=0):
        sys.exit("positions differ between ParaView and the snapshot")
    for name in names:
        if name not in data.PointData.keys():
            sys.exit(f"ParaView shows no array '{name}'; it shows {sorted(data.PointData.keys())}")
        shown = np.asarray(data.PointData[name])
        # The h5 side: a dataset of that name, or a column of a multi-column dataset found by
        # its 'columns' attribute (species_Fe2O3 = /particles/species column 'Fe2O3').
        expected = None
        for group in ("particles", "contacts"):
            for ds_name, ds in h5[group].items():
                if ds_name == name:
                    expected = ds[()]
                elif name.startswith(ds_name + "_") and "columns" in ds.attrs:
                    columns = ds.attrs["columns"]
                    columns = columns.decode() if isinstance(columns, bytes) else str(columns)
                    column = name[len(ds_name) + 1:]
                    if column in columns.split(","):
                        expected = ds[()][:, columns.split(",").index(column)]
        if expected is None:
            sys.exit(f"no dataset in the snapshot for '{name}'")
        shown = shown.reshape(expected.shape)
        if not np.allclose(shown, expected, rtol=1e-12, atol=0):
            sys.exit(f"{name}: ParaView and the snapshot differ (max |diff| "
                     f"{np.max(np.abs(shown - expected))})")
        print(f"{name}: {expected.size} values equal, range [{expected.min()}, {expected.max()}]")
print(f"t = {t} s, {len(points)} particles: OK")
