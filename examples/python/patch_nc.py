"""Patch an NC program through polepatch's C ABI with ctypes.

    python3 patch_nc.py path/to/libpolepatch_capi.so MACHINE INPUT OUTPUT

Build the library with `cargo build --release -p polepatch-capi` (target/release/
libpolepatch_capi.so on Linux, .dylib on macOS, polepatch_capi.dll on Windows). The
declarations mirror crates/capi/include/polepatch.h.
"""

import ctypes
import json
import sys


class PpBuffer(ctypes.Structure):
    _fields_ = [("data", ctypes.POINTER(ctypes.c_uint8)), ("len", ctypes.c_size_t)]


class PpOptions(ctypes.Structure):
    _fields_ = [
        ("cone_deg", ctypes.c_double),
        ("margin", ctypes.c_double),
        ("max_decimals", ctypes.c_uint32),
        ("max_deviation_deg", ctypes.c_double),
        ("only_c", ctypes.c_bool),
        ("allow_c_offset", ctypes.c_bool),
        ("tcy_ms", ctypes.c_double),
        ("feed_fallback_mm_min", ctypes.c_double),
        ("has_work_offset", ctypes.c_bool),
        ("work_offset_mm", ctypes.c_double * 3),
        ("name", ctypes.c_char_p),
        # Added with issue 27 (after `name`): the tool, as the CLI's --tool, --tool-point
        # and --surface-tolerance. Start from pp_options_default().
        ("tool_kind", ctypes.c_int32),  # 0 none given, 1 ball, 2 flat, 3 bull-nose
        ("tool_diameter_mm", ctypes.c_double),
        ("tool_corner_radius_mm", ctypes.c_double),
        ("tool_point", ctypes.c_int32),  # 0 as the program says, 1 tip, 2 centre
        ("surface_tolerance_mm", ctypes.c_double),  # <= 0: 0.005
    ]


PP_OK = 0


def load(path):
    lib = ctypes.CDLL(path)
    lib.pp_machine_builtin.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_void_p)]
    lib.pp_machine_builtin.restype = ctypes.c_int
    lib.pp_machine_free.argtypes = [ctypes.c_void_p]
    lib.pp_options_default.restype = PpOptions
    lib.pp_patch_nc.argtypes = [
        ctypes.c_void_p,
        ctypes.c_char_p,
        ctypes.c_size_t,
        ctypes.POINTER(PpOptions),
        ctypes.POINTER(PpBuffer),
        ctypes.POINTER(PpBuffer),
    ]
    lib.pp_patch_nc.restype = ctypes.c_int
    lib.pp_buffer_free.argtypes = [ctypes.POINTER(PpBuffer)]
    lib.pp_last_error.restype = ctypes.c_char_p
    return lib


def main(lib_path, machine_name, input_path, output_path):
    lib = load(lib_path)
    machine = ctypes.c_void_p()
    if lib.pp_machine_builtin(machine_name.encode(), ctypes.byref(machine)) != PP_OK:
        sys.exit("machine: " + lib.pp_last_error().decode())
    with open(input_path, "rb") as f:
        data = f.read()
    opts = lib.pp_options_default()
    opts.name = input_path.encode()
    out, report = PpBuffer(), PpBuffer()
    status = lib.pp_patch_nc(machine, data, len(data), ctypes.byref(opts), ctypes.byref(out), ctypes.byref(report))
    if status != PP_OK:
        lib.pp_machine_free(machine)
        sys.exit("patch: " + lib.pp_last_error().decode())
    try:
        with open(output_path, "wb") as f:
            f.write(ctypes.string_at(out.data, out.len))
        doc = json.loads(ctypes.string_at(report.data, report.len))
        reached = sum(1 for z in doc["zones"] if z["outcome"] == "reached")
        print(f"{doc['file']}: {len(doc['zones'])} zone(s), {reached} reach feed, {doc['words_changed']} words changed")
    finally:
        lib.pp_buffer_free(ctypes.byref(out))
        lib.pp_buffer_free(ctypes.byref(report))
        lib.pp_machine_free(machine)


if __name__ == "__main__":
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    main(*sys.argv[1:])
