"""rod.intrinsic_curvature_per_A = [Ω¹₀, Ω²₀] reaches the rod's energy: the bending energy
E = (Δs/2) Σ a [(Ω¹ − Ω¹₀)² + (Ω² − Ω²₀)²] of the untwisted circle (each segment turns by
2π/n, so |Ω| = 2 sin(π/n)/Δs about one body axis) in closed form for each reference curvature.
(F = −∂E/∂X with intrinsic curvature: tests/unit/rod/test_forces.cpp.)"""
import numpy as np
import pytest

import ibrod

N, DS = 100, 3.4
A = 1.3e-19 * 1e24               # a1 = a2: erg·cm → g Å³ s⁻²
KT = 1.380649e-16 * 300 * 1e16   # g Å² s⁻²


def bend_energy_kT(cfg, kappa):
    c = cfg.copy()
    c["rod.intrinsic_curvature_per_A"] = list(kappa)
    sim = ibrod.Simulation(c)
    sim.run(steps=1)
    return sim.observables()["E_bend_kT"][0]  # the row of step 0


def test_bending_energy_against_the_reference_curvature(cfg):
    cfg.update({"rod.excess_link": 0, "rod.perturbation": [], "electrostatics.enabled": False,
                "steric.enabled": False})
    k = 2 * np.sin(np.pi / N) / DS
    e0 = bend_energy_kT(cfg, (0, 0))
    assert e0 == pytest.approx(N * DS / 2 * A * k**2 / KT, rel=1e-9)
    e = {kappa: bend_energy_kT(cfg, kappa) for kappa in ((k, 0), (-k, 0), (0, k), (0, -k))}
    # one reference matches the circle (no bending energy), its opposite doubles the strain,
    # the two about the other axis add to it in quadrature
    assert min(e.values()) < 1e-9 * e0
    assert max(e.values()) == pytest.approx(4 * e0, rel=1e-9)
    assert sorted(e.values())[1:3] == pytest.approx([2 * e0, 2 * e0], rel=1e-9)


def test_bad_intrinsic_curvature_is_refused():
    c = ibrod.Config()
    for bad, words in (([0.1], "two numbers"), (0.1, "two numbers"), ([0.1, 0.2, 0.3], "two")):
        with pytest.raises(ibrod.ConfigError) as e:
            c["rod.intrinsic_curvature_per_A"] = bad
        assert "rod.intrinsic_curvature_per_A" in str(e.value) and words in str(e.value)
    assert c["rod.intrinsic_curvature_per_A"] == [0.0, 0.0]  # unchanged by a refusal
    c["rod.intrinsic_curvature_per_A"] = [0.5, 0]  # |Ω₀| Δs > π/2: refused by the cross check
    with pytest.raises(ibrod.ConfigError) as e:
        c.validate()
    assert "rod.intrinsic_curvature_per_A" in str(e.value)
