#!/usr/bin/python3
"""Seed files for the file-reader fuzz harnesses (tests/fuzz/run_fuzz.sh), in the formats triaxdem writes:
a snapshot with contacts and a membrane surface (as the triaxial job writes at a micro record), measured data
in HDF5 form (for the raw HDF5 harness), and the tables of fuzz_tables (its first byte picks the reader). Checkpoints and plain snapshots
come from a short run of triaxdem itself.
    make_seeds.py OUT_DIR        (writes OUT_DIR/snapshot/, OUT_DIR/measured.h5 and OUT_DIR/tables/)"""
import os
import sys

import h5py
import numpy as np

out = sys.argv[1]
os.makedirs(os.path.join(out, "snapshot"), exist_ok=True)
os.makedirs(os.path.join(out, "tables"), exist_ok=True)

with h5py.File(os.path.join(out, "snapshot", "micro_snapshot.h5"), "w") as f:
    f.attrs["label"] = np.bytes_("shear eps_a=1%")
    f["x"] = np.array([[0, 0, 0], [2e-3, 0, 0], [4e-3, 0, 0]], dtype=float)
    f["radius"] = np.full(3, 1e-3)
    f["gid"] = np.arange(3, dtype=np.uint32)
    f["surface/nodes"] = np.array([[0, -1e-3, 0], [4e-3, -1e-3, 0], [0, -1e-3, 1e-3]], dtype=float)
    f["surface/triangles"] = np.array([[0, 1, 2]], dtype=np.int32)
    c = f.create_group("contacts")
    c["a"] = np.array([0, 1, 2], dtype=np.int32)
    c["b"] = np.array([1, 2, -1], dtype=np.int32)
    c["boundary"] = np.array([0, 0, 2], dtype=np.int32)
    c["fn"] = np.ones(3)
    for name, row in (("normal", [1, 0, 0]), ("point", [1e-3, 0, 0]), ("branch", [2e-3, 0, 0]), ("ft", [0, 0.1, 0])):
        c[name] = np.tile(np.array(row, dtype=float), (3, 1))

with h5py.File(os.path.join(out, "measured.h5"), "w") as f:
    t = f.create_dataset("S-1/table", data=np.array([[100, 0, 0], [100, 1, 150], [100, 2, 160]], dtype=float))
    t.attrs["columns"] = np.bytes_("sigma3_kPa,eps_a_pct,q_kPa")

tables = {
    "summary": (0, b"case,material,sigma3_kPa,q_peak_kPa,eps_a_peak_pct,phi_peak_deg\nS1,S-1,100,150.2,3.1,27.5\n"),
    "reference": (1, b"material,mu_s,mu_r\nS-1,0.15,0.02\nS-3,0.3,0.05\n"),
    "specimen": (2, b"# triaxdem specimen\n# key fuzz\n# height_m 0.016 void_ratio 0.7\n"
                    b"# layer 0 0.008 0.0081 0.71 1200 0.001\n# profile 0.4 0.41\nx_m,y_m,z_m,radius_m,density_kg_m3\n"
                    b"0.001,0.002,0.001,0.001,2500\n0.003,0.002,0.001,0.001,2500\n"),
}
for name, (selector, body) in tables.items():
    with open(os.path.join(out, "tables", name), "wb") as f:
        f.write(bytes([selector]) + body)
