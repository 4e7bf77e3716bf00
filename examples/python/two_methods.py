"""Deform the survey bar's look-alike with two methods and print their measures.

Run from the repository root after `pip install ./deformbench-py` (README, "From Python").
"""

import deformbench

s = deformbench.load_scenario("configs/scenarios/bar.toml")  # the survey bar's look-alike
print(s)
for name in ["arap", "hirm"]:
    m = deformbench.Method(name, s.V, s.F)  # precompute (parameters as keyword arguments)
    m.bind(s.fixed(), s.handles())  # fixed vertices, handle regions
    V1 = m.solve(s.targets())  # one #h_i x 3 array of targets per handle
    v = deformbench.verdict(s.V, s.F, V1, fixed=s.fixed(), handles=s.handles(), targets=s.targets())
    e = v["measures"]
    print(
        f"{name:5} {m.iterations:4} iterations {m.solve_seconds:6.2f} s  {v['status']:8}"
        f"  e_iso {e['e_iso']:.4f}  E_theta {e['e_theta_deg']:.2f} deg  area {e['area_change']:+.3f}"
    )
