"""Bad input raises InputError with where it is; bad machines MachineError; bad options
ValueError naming them; a panic InternalError — never a crash."""

from __future__ import annotations

import os

import pytest

import polepatch
from conftest import read


def test_the_issue_check_a_syntax_error_has_line_and_column() -> None:
    with pytest.raises(polepatch.InputError) as info:
        polepatch.patch_nc(b"N10 G01 X1..2 *\n", machine="mikron-ucp710")
    e = info.value
    assert isinstance(e, ValueError)
    assert (e.line, e.column) == (1, 9), str(e)  # the X word starts at byte 9
    assert e.path is None  # no name given
    assert "1..2" in str(e)


def test_attributes_name_the_input_when_named() -> None:
    program = b"%P G71 *\nN10 G01 X0 Y0 Z0 A1 C0 F1000 *\nN20 X1 C1..5 *\n"
    with pytest.raises(polepatch.InputError) as info:
        polepatch.patch_nc(program, "mikron-ucp710", name="part.I")
    e = info.value
    assert (e.path, e.line, e.column) == ("part.I", 3, 8), str(e)
    assert str(e).startswith("part.I:3:8: ")
    with pytest.raises(polepatch.InputError) as info:
        polepatch.analyze_nc(program, "mikron-ucp710", name="part.I")
    assert (info.value.line, info.value.column) == (3, 8)


def test_an_empty_program_is_an_input_error_with_a_path_and_no_line() -> None:
    with pytest.raises(polepatch.InputError) as info:
        polepatch.patch_nc(b"  \n\n", "mikron-ucp710", name="p.nc")
    e = info.value
    assert e.path == "p.nc" and e.line is None and e.column is None, str(e)


def test_programs_without_work_come_back_unchanged_with_a_warning() -> None:
    for program, why in [
        (b"%P G71 *\nN10 G00 X0 Y0 Z0 *\n", "no G1 motion"),
        (b"%P G71 *\nN10 G01 X0 Y0 Z0 F100 *\nN20 X1 Y1 Z0 *\n", "no rotary axis words"),
    ]:
        out, report = polepatch.patch_nc(program, "mikron-ucp710", name="p.nc")
        assert out == program
        assert report["zones"] == []
        assert any(why in w for w in report["warnings"]), report["warnings"]


def test_a_bad_cl_record_has_line_and_column() -> None:
    cl = "MULTAX/ON\nFEDRAT/1000,MMPM\nGOTO/1,2,3,0,0,1\nGOTO/1,2,3.5.1,0,0,1\n"
    with pytest.raises(polepatch.InputError) as info:
        polepatch.post_cl(cl, "mikron-ucp710", name="bad.apt")
    e = info.value
    assert (e.path, e.line) == ("bad.apt", 4), str(e)
    assert e.column is not None and cl.splitlines()[3][e.column - 1 :].startswith("3.5.1")


def test_an_unsupported_point_has_a_line() -> None:
    # No feed anywhere, and none given: refused at the first move, by line.
    cl = "MULTAX/ON\nGOTO/0,0,0,0,0,1\nGOTO/1,0,0,0,0.6,0.8\n"
    with pytest.raises(polepatch.InputError) as info:
        polepatch.post_cl(cl, "mikron-ucp710")
    assert (info.value.line, info.value.column) == (2, 1), str(info.value)
    assert "feed" in str(info.value)
    assert polepatch.post_cl(cl, "mikron-ucp710", feed_fallback_mm_min=1000.0)


# A machine of one's own (the UCP710's figures, another name and cycle time).
MACHINE_TOML = """
name = "shop-ac"
tcy_ms = 2.0
[x]
v_m_min = 30.0
a_m_s2 = 2.5
j_m_s3 = 5.0
[y]
v_m_min = 30.0
a_m_s2 = 3.0
j_m_s3 = 5.0
[z]
v_m_min = 30.0
a_m_s2 = 2.1
j_m_s3 = 50.0
[primary]
letter = "A"
sense = 1
range_deg = [-100.0, 120.0]
v_rpm = 15.0
a_rev_s2 = 0.83
j_rev_s3 = 5.0
[c]
sense = 1
v_rpm = 20.0
a_rev_s2 = 0.83
j_rev_s3 = 50.0
"""


def test_a_machine_from_toml_is_used_like_a_built_in(tmp_path) -> None:
    m = polepatch.Machine.from_toml(MACHINE_TOML)
    assert (m.name, m.primary, m.tcy_ms, m.c_range_deg) == ("shop-ac", "A", 2.0, None)
    path = tmp_path / "shop.toml"
    path.write_text(MACHINE_TOML)
    assert polepatch.Machine.from_file(path).limits == m.limits
    out, report = polepatch.patch_nc(read("fixtures/c17/SING.I"), m)
    assert report["machine"] == "shop-ac" and report["zones"]


def test_a_machine_file_is_read_to_a_bound() -> None:
    # Issue 26: `/dev/zero` was read without limit.
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero on this system")
    with pytest.raises(polepatch.MachineError, match="longer than"):
        polepatch.Machine.from_file("/dev/zero")


def test_machines() -> None:
    with pytest.raises(polepatch.MachineError, match="mikron-ucp710, mikron-hsm600"):
        polepatch.Machine.builtin("mikron-ucp999")
    with pytest.raises(polepatch.MachineError, match="mikron-ucp999"):
        polepatch.patch_nc(b"G1 X0\n", machine="mikron-ucp999")
    with pytest.raises(polepatch.MachineError, match="missing field"):
        polepatch.Machine.from_toml("[x]\nv_m_min = 30\n")
    with pytest.raises(polepatch.MachineError, match=r"x\.v_m_min must be positive.*-1"):
        polepatch.Machine.from_toml(MACHINE_TOML.replace("v_m_min = 30.0", "v_m_min = -1.0", 1))
    assert issubclass(polepatch.MachineError, ValueError)
    with pytest.raises(TypeError):
        polepatch.patch_nc(b"G1 X0\n", machine=42)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    "option, value",
    [
        ("cone_deg", -1.0),
        ("cone_deg", float("nan")),
        ("margin", 0.5),
        ("max_decimals", 10),
        ("max_deviation_deg", 0.0),
        ("tcy_ms", -1.0),
        ("max_patch_length_mm", float("inf")),
        ("feed_fallback_mm_min", 0.0),
        ("work_offset_mm", (0.0, float("nan"), 0.0)),
    ],
)
def test_bad_options_are_value_errors_naming_them(option: str, value: object) -> None:
    data = read("fixtures/c17/SING.I")
    with pytest.raises(ValueError) as info:
        polepatch.patch_nc(data, "mikron-ucp710", **{option: value})
    assert not isinstance(info.value, polepatch.InputError)
    assert option.split("_")[0] in str(info.value), str(info.value)


def test_bad_arguments_of_the_other_calls() -> None:
    data = read("fixtures/c17/SING.I")
    with pytest.raises(ValueError, match="theta_x and theta_z"):
        polepatch.reorient(data, "mikron-ucp710", theta_x=10.0)
    with pytest.raises(ValueError, match="cone_deg"):
        polepatch.reorient(data, "mikron-ucp710", 10.0, 0.0, cone_deg=0.0)
    with pytest.raises(ValueError, match="cone_deg"):
        polepatch.analyze_nc(data, "mikron-ucp710", cone_deg=-5.0)
    with pytest.raises(ValueError, match="dialect must be one of heidenhain"):
        polepatch.post_cl("GOTO/0,0,0,0,0,1\n", "mikron-ucp710", "haas")
    with pytest.raises(ValueError, match="rotary_decimals"):
        polepatch.post_cl("GOTO/0,0,0,0,0,1\n", "mikron-ucp710", rotary_decimals=12)
    with pytest.raises(TypeError, match="bytes"):
        polepatch.patch_nc("G1 X0", "mikron-ucp710")  # type: ignore[arg-type]


def test_array_errors_name_the_row() -> None:
    cl = [[0, 0, 0, 0, 0, 1], [1, 0, 0, 0, 0, 0]]
    with pytest.raises(polepatch.InputError) as info:
        polepatch.cl_to_joints(cl, "mikron-ucp710")
    assert info.value.index == 1 and "zero" in str(info.value)
    with pytest.raises(ValueError, match=r"shape \(n, 6\)"):
        polepatch.cl_to_joints([[0, 0, 1]], "mikron-ucp710")
    with pytest.raises(ValueError, match="branch must be one of"):
        polepatch.cl_to_joints([[0, 0, 0, 0, 0, 1]], "mikron-ucp710", branch="up")
    still = [[0, 0, 0, 1, 0], [0, 0, 0, 2, 90]]
    with pytest.raises(polepatch.InputError) as info:
        polepatch.patch_joints(still, "mikron-ucp710", 1000.0)
    assert info.value.index == 1 and "same tool tip" in str(info.value)
    with pytest.raises(polepatch.InputError, match="at least 2"):
        polepatch.patch_joints([[0, 0, 0, 1, 0]], "mikron-ucp710", 1000.0)
    with pytest.raises(polepatch.InputError, match="feed"):
        polepatch.patch_joints([[0, 0, 0, 1, 0], [1, 0, 0, 1, 0]], "mikron-ucp710", -5.0)
    with pytest.raises(polepatch.InputError) as info:
        polepatch.patch_joints([[0, 0, 0, 1, 0], [1, 0, float("nan"), 1, 0]], "mikron-ucp710", 1e3)
    assert info.value.index == 1


def test_a_panic_becomes_internal_error_not_a_crash() -> None:
    with pytest.raises(polepatch.InternalError, match="please report.*boom 42"):
        polepatch._polepatch._panic_for_test("boom 42")
    # The interpreter and the package still work afterwards.
    assert polepatch.Machine.builtin("mikron-ucp710").primary == "A"


def test_cl_to_joints_refuses_a_joint_value_outside_the_range() -> None:
    """Issue 26 item 4: a tool axis pointing down needs A = 180° on the UCP710, whose A
    ends at 120°: an InputError naming the row, never an out-of-range result."""
    import numpy as np

    with pytest.raises(polepatch.InputError) as e:
        polepatch.cl_to_joints(np.array([[0, 0, 0, 0, 0, 1.0], [1, 0, 0, 0, 0, -1.0]]), "mikron-ucp710")
    assert e.value.index == 1
    assert "180" in str(e.value) and "120" in str(e.value)


@pytest.mark.parametrize(
    "option, value, message",
    [
        ("max_deviation_deg", 0.0, "max_deviation_deg must be a positive number of degrees, got 0"),
        ("margin", -0.1, "margin must be a fraction in [0, 0.5), got -0.1"),
        ("max_decimals", 12, "max_decimals must be at most 9, got 12"),
    ],
)
def test_options_are_refused_by_the_patchers_rules(option: str, value: object, message: str) -> None:
    """Issue 28 §3: the patcher's one rule set, naming the keyword (the CLI names its flag)."""
    data = read("fixtures/c17/SING.I")
    with pytest.raises(ValueError) as info:
        polepatch.patch_nc(data, "mikron-ucp710", **{option: value})
    assert str(info.value).startswith(message), str(info.value)
