#!/usr/bin/python3
"""Writes the nine cases of Tang et al. (2025) as triaxdem configs: S-1, S-2, S-3 (mu_s, mu_r of Table 5) at
sigma3 = 100, 200, 300 kPa, full scale in configs/paper/ and scaled down in configs/small/.

    /usr/bin/python3 scripts/paper_configs.py      # from the repository root; rewrites both folders

The choices where the paper is ambiguous are written into each file as comments.
"""
import os

MATERIALS = {"S1": (0.15, 0.015), "S2": (0.3, 0.02), "S3": (0.4, 0.025)}  # Table 5
PRESSURES = (100, 200, 300)  # kPa, Sec. 2.3

SCALES = {
    "paper": dict(
        title="full scale: 53,704 beads of 2 mm in 61.8 mm x 120 mm (Sec. 3.3)",
        diameter=61.8, height=120.0, size_line="ball_count = 53704        # the paper's count (Sec. 3.3)",
        size_note="""# Choice: 53,704 balls, the paper's count. In the nominal 61.8 x 120 mm cylinder that is e = 0.600, the
# lab value of Sec. 2.3; Table 4's e = 0.61 would give 53,373 balls. We follow the count (and the lab).""",
        record=0.1, around=81, segments=20, rve=20.0,
        settle="settle_mu_s = 0.15        # friction once a layer is pressed: the wide layers settle in far fewer steps\n"),
    "small": dict(
        title="scaled down for tests and quick looks: about 3,700 beads of 2 mm in 25 mm x 50 mm",
        diameter=25.0, height=50.0, size_line="void_ratio = 0.60          # the paper's (and the lab's) e",
        size_note="""# Scaled down: 12.5 beads across instead of 31, so the looser packing along the mould weighs more
# and q_peak is not to be compared with Table 6 at better than about 10%.""",
        record=0.1, around=81, segments=20, rve=12.0, settle=""),
}

TEMPLATE = """# Drained triaxial test of Tang et al. (2025), {mat_name} beads at sigma3 = {p} kPa, {title}.
#   triaxdem triaxial {path}
# Written by scripts/paper_configs.py; edit that script, not this file.
{size_note}
# Choices where the paper is ambiguous (../shared/data/table1_4_parameters.csv):
# - E* = 1e8 Pa: Table 4 prints "1e8 N/mm2"; with kn = A E*/L only Pa gives the usual PFC stiffness.
# - Shear rate: a quasi-static inertial number of 1e-3 instead of the lab's 0.24 mm/min (Table 4 also says
#   0.04 mm/min); with density scaling x100 this is about 20 s of simulated time to 15% strain.
# - Membrane: Table 4's Poisson's ratio 0.2 is the glass's (Table 1); the latex membrane gets 0.49 and a
#   typical latex modulus of 1.4 MPa (the paper gives none); thickness and density are Table 4's.
# - Gravity off: the self-weight stress at the base (about 1.8 kPa) is under 2% of sigma3, and density
#   scaling would multiply it by 100.
[run]
name = "{name}"
material = "{mat_name}"          # Table 6's sample: `triaxdem study --compare data/tang2025_table6_peak.csv` matches it
output = "out/{outdir}"
seed = 1

[particles]
diameter_mm = 2.0
density_kg_m3 = 2500      # glass (Table 1)

[specimen]
diameter_mm = {diameter}
height_mm = {height}
{size_line}
layers = 5                # five equal layers (Sec. 3.3)
compaction_mu_s = 0.0     # frictionless while compacting, so that the platen can reach the target density
{settle}platen_speed_mm_s = 200.0  # fast enough to compact 53,704 beads in minutes; impacts squeeze the beads by about 1% of the radius
stop_ratio = 1e-3         # unbalanced-force ratio that ends each layer (Sec. 3.3)

[triaxial]
sigma3_kPa = {p}
axial_strain_end_pct = 15.0
inertial_number = 1e-3
record_every_pct = {record}
membrane_nodes_around = {around}
membrane_segments = {segments}
membrane_modulus_MPa = 1.4
membrane_poisson = 0.49
membrane_thickness_mm = 0.5
membrane_density_kg_m3 = 930

[micro]                   # recorded with every row of the series; distributions at A-D and at the peak
rve_edge_mm = {rve}       # central cube of the micro statistics (the paper's 20 mm where it fits)
rose_bins = 18

[material]                # rolling resistance linear, deformability method (Table 4), {mat_name} of Table 5
emod_Pa = 1.0e8
kratio = 1.5
mu_s = {mu_s}
mu_r = {mu_r}

[solver]
damping = 0.7             # local damping (Table 4)
gravity = [0.0, 0.0, 0.0]
mass_scale = 100.0        # density scaling: quasi-static runs only (labelled in the output)
# E* = 1e8 Pa makes the beads some 700 times softer than glass: at sigma3 = 300 kPa the strongest chains
# overlap by up to 10% of the radius (mean 1.3%, 99.9th percentile 7.6% in the scaled-down S-3 case), which
# is the model's physics, not a numerical blow-up; the guard is set above it.
overlap_limit = 0.25
"""


def main():
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    for scale, s in SCALES.items():
        folder = os.path.join(root, "configs", scale)
        os.makedirs(folder, exist_ok=True)
        for mat, (mu_s, mu_r) in MATERIALS.items():
            for p in PRESSURES:
                stem = f"{mat}_{p}kPa"
                path = f"configs/{scale}/{stem}.toml"
                text = TEMPLATE.format(mat_name=f"S-{mat[1]}", p=p, title=s["title"], path=path,
                                       size_note=s["size_note"], name=f"{scale} {mat} {p} kPa",
                                       outdir=f"{scale}_{stem}", diameter=s["diameter"], height=s["height"],
                                       size_line=s["size_line"], record=s["record"], around=s["around"],
                                       segments=s["segments"], rve=s["rve"], settle=s["settle"], mu_s=mu_s, mu_r=mu_r)
                with open(os.path.join(root, path), "w") as f:
                    f.write(text)
                print("wrote", path)


if __name__ == "__main__":
    main()
