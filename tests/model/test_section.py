"""Multilayer cross-sections against the thesis (Metello 2020, eqs. 3.1-3.6, Tables 4.1-4.3)."""
from dataclasses import replace

import pytest

from mjeap.model.catalog import CATALOG, PVDF_60, PVDF_60_HALF, PVDF_130, PZT_HAMR_LARGE
from mjeap.model.section import SectionLayer, multilayer_section

L_FREE = 52e-3  # m, thesis Table 3.4


def test_60pvdf_neutral_axis_and_EI_match_thesis():
    """Thesis result for 60PVDF: z_c = 0.132 mm, EI = 2.703e7 Pa mm^4; tolerance 1 %."""
    s = PVDF_60.section_at(0.0)
    assert s.plane_strain  # 15 mm wide, 0.277 mm thick: the thesis's plane-strain rule applies
    assert s.neutral_axis == pytest.approx(0.132e-3, rel=0.01)
    assert s.flexural_rigidity == pytest.approx(2.703e-5, rel=0.01)


def tip_stiffness(act, plane_strain=None):
    """3 EI / L^3 in N/mm (the unit of the thesis tables)."""
    a = act if plane_strain is None else replace(act, plane_strain=plane_strain)
    return 3 * a.section_at(0.0).flexural_rigidity / L_FREE**3 * 1e-3


def test_tip_stiffness_against_thesis_model_slopes():
    """Tables 4.1-4.3, column 'Model' (N/mm): 60PVDF 5.00e-4, 60PVDFHalf 2.90e-4, 130PVDF 8.60e-4.

    The thesis's own table is not consistent with its eq. 3.6: 60PVDF's slope is 3EI/L^3
    with the uniaxial modulus (within 1 %; the plane-strain EI of eq. 3.6, which the
    thesis reports as 2.703e7 Pa mm^4, gives 15 % more), 60PVDFHalf's matches the
    plane-strain EI within 4 %, and 130PVDF's matches neither (> 15 % below both). The
    catalog keeps the thesis's eq. 3.1 rule (plane strain) and this test pins the
    disagreement so that it is reported, not tuned away.
    """
    assert tip_stiffness(PVDF_60, plane_strain=False) == pytest.approx(5.00e-4, rel=0.01)
    assert tip_stiffness(PVDF_60) / 5.00e-4 - 1 == pytest.approx(0.152, abs=0.01)
    assert tip_stiffness(PVDF_60_HALF) == pytest.approx(2.90e-4, rel=0.04)
    for ps in (True, False):
        assert tip_stiffness(PVDF_130, plane_strain=ps) / 8.60e-4 - 1 > 0.15


def test_symmetric_bimorph_matches_wood_formula():
    """Wood et al. 2005: D = (1/3) E_p t_p (1.5 t_cf^2 + 3 t_cf t_p + 2 t_p^2) + E_cf t_cf^3 / 12 per width."""
    a = PZT_HAMR_LARGE
    Ep, tp = a.layers[0].youngs_modulus, a.layers[0].thickness
    Ecf, tcf = a.layers[1].youngs_modulus, a.layers[1].thickness
    D = Ep * tp * (1.5 * tcf**2 + 3 * tcf * tp + 2 * tp**2) / 3 + Ecf * tcf**3 / 12
    for x in (0.0, 0.5 * a.length, a.length):
        s = a.section_at(x)
        assert s.neutral_axis == pytest.approx(160e-6, rel=1e-12)
        assert s.flexural_rigidity == pytest.approx(D * float(a.width_at(x)), rel=1e-12)


def test_homogeneous_strip_is_wt3_over_12():
    s = multilayer_section([SectionLayer(1e-3, 2e-3, 1e9, 0.3, 1000.0)], plane_strain=False)
    assert s.flexural_rigidity == pytest.approx(1e9 * 2e-3 * 1e-9 / 12, rel=1e-12)
    assert s.neutral_axis == pytest.approx(0.5e-3)
    assert s.mass_per_length == pytest.approx(1000 * 2e-6)


def test_every_catalog_number_has_a_source():
    for a in CATALOG.values():
        assert a.document and a.planform.source and a.damping_ratio.source and a.voltage_source
        for layer in a.layers:
            for f in ("thickness", "width", "youngs_modulus", "poisson_ratio", "density"):
                assert layer.provenance(f), (a.id, layer.name, f)


def test_pedot_uses_identified_EI_and_measured_mass():
    a = CATALOG["pedot-micro"]
    assert a.flexural_rigidity_at(0.003)[0] == pytest.approx(1 / 4.86e7, rel=1e-12)
    assert a.total_mass() == pytest.approx(0.695e-6, rel=1e-12)
