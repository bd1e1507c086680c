/* Patch an NC file through the polepatch C ABI, and check the ABI's refusals.
 *
 *   patch_file MACHINE INPUT OUTPUT REPORT.json NAME [BALL_OUTPUT BALL_REPORT.json]
 *
 * With the last two, the file is also patched for a D10 ball-end mill programmed at its
 * tip (tool_kind, tool_diameter_mm, tool_point: the CLI's --tool ball:10 --tool-point
 * tip) and that output and report written there.
 * Exit 0 when the file was patched and every bad call gave the expected status with a
 * message; otherwise a message on stderr and exit 1. Built and run by tests/c_program.rs. */
#include "polepatch.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures = 0;

static void expect(const char *what, PpStatus got, PpStatus want) {
    const char *msg = pp_last_error();
    if (got != want) {
        fprintf(stderr, "%s: status %d, expected %d (%s)\n", what, (int)got, (int)want, msg);
        failures++;
    } else if (want != PP_OK && (msg == NULL || msg[0] == '\0')) {
        fprintf(stderr, "%s: no message from pp_last_error\n", what);
        failures++;
    }
}

static unsigned char *read_file(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc(n > 0 ? (size_t)n : 1);
    *len = fread(buf, 1, (size_t)n, f);
    fclose(f);
    return buf;
}

static int write_file(const char *path, const PpBuffer *b) {
    FILE *f = fopen(path, "wb");
    if (!f) return 1;
    size_t w = b->len ? fwrite(b->data, 1, b->len, f) : 0;
    fclose(f);
    return w != b->len;
}

int main(int argc, char **argv) {
    if (argc != 6 && argc != 8) {
        fprintf(stderr, "usage: patch_file MACHINE INPUT OUTPUT REPORT NAME [BALL_OUTPUT BALL_REPORT]\n");
        return 2;
    }
    PpMachine *m = NULL;
    expect("builtin", pp_machine_builtin(argv[1], &m), PP_OK);
    if (!m) return 1;

    size_t len = 0;
    unsigned char *input = read_file(argv[2], &len);
    if (!input) {
        fprintf(stderr, "cannot read %s\n", argv[2]);
        return 1;
    }
    PpOptions opts = pp_options_default();
    opts.name = argv[5];
    PpBuffer out = {0}, report = {0};
    expect("patch", pp_patch_nc(m, input, len, &opts, &out, &report), PP_OK);
    if (write_file(argv[3], &out) || write_file(argv[4], &report)) {
        fprintf(stderr, "cannot write the outputs\n");
        failures++;
    }
    pp_buffer_free(&out);
    pp_buffer_free(&report);
    pp_buffer_free(&out); /* freeing twice is harmless: the buffer was emptied */

    if (argc == 8) {
        PpOptions ball = pp_options_default();
        if (ball.tool_kind != PP_TOOL_NONE || ball.tool_point != PP_TOOL_POINT_PROGRAM) {
            fprintf(stderr, "pp_options_default gives a tool\n");
            failures++;
        }
        ball.name = argv[5];
        ball.tool_kind = PP_TOOL_BALL;
        ball.tool_diameter_mm = 10.0;
        ball.tool_point = PP_TOOL_POINT_TIP;
        PpBuffer bout = {0}, breport = {0};
        expect("patch ball:10 at the tip", pp_patch_nc(m, input, len, &ball, &bout, &breport), PP_OK);
        if (write_file(argv[6], &bout) || write_file(argv[7], &breport)) {
            fprintf(stderr, "cannot write the ball outputs\n");
            failures++;
        }
        pp_buffer_free(&bout);
        pp_buffer_free(&breport);
    }

    /* Refusals: the right status, a message, no crash. */
    PpBuffer junk_out = {0};
    expect("NULL machine", pp_patch_nc(NULL, input, len, NULL, &junk_out, NULL), PP_BAD_MACHINE);
    expect("NULL input", pp_patch_nc(m, NULL, 10, NULL, &junk_out, NULL), PP_BAD_INPUT);
    expect("zero length", pp_patch_nc(m, input, 0, NULL, &junk_out, NULL), PP_BAD_INPUT);
    expect("NULL output", pp_patch_nc(m, input, len, NULL, NULL, NULL), PP_BAD_INPUT);
    unsigned char binary[64];
    for (int i = 0; i < 64; i++) binary[i] = (unsigned char)(i * 37 + 11);
    expect("binary junk", pp_patch_nc(m, binary, sizeof binary, NULL, &junk_out, NULL), PP_BAD_INPUT);
    PpMachine *bad = NULL;
    expect("unknown machine", pp_machine_builtin("mikron-ucp999", &bad), PP_BAD_MACHINE);
    expect("NULL name", pp_machine_builtin(NULL, &bad), PP_BAD_INPUT);
    expect("bad TOML", pp_machine_from_toml("name = [", &bad), PP_BAD_MACHINE);
    expect("TOML missing fields", pp_machine_from_toml("name = \"x\"\n", &bad), PP_BAD_MACHINE);
    PpOptions wrong = pp_options_default();
    wrong.margin = 0.9;
    expect("bad option", pp_patch_nc(m, input, len, &wrong, &junk_out, NULL), PP_BAD_INPUT);
    PpOptions wrong_tool = pp_options_default();
    wrong_tool.tool_kind = 7;
    expect("bad tool kind", pp_patch_nc(m, input, len, &wrong_tool, &junk_out, NULL), PP_BAD_INPUT);
    wrong_tool = pp_options_default();
    wrong_tool.tool_kind = PP_TOOL_BULL;
    wrong_tool.tool_diameter_mm = 10.0;
    wrong_tool.tool_corner_radius_mm = 6.0; /* more than half the diameter */
    expect("bad corner radius", pp_patch_nc(m, input, len, &wrong_tool, &junk_out, NULL), PP_BAD_INPUT);
    wrong_tool = pp_options_default();
    wrong_tool.tool_kind = PP_TOOL_FLAT; /* no diameter */
    expect("no diameter", pp_patch_nc(m, input, len, &wrong_tool, &junk_out, NULL), PP_BAD_INPUT);
    wrong_tool = pp_options_default();
    wrong_tool.tool_point = 3;
    expect("bad tool point", pp_patch_nc(m, input, len, &wrong_tool, &junk_out, NULL), PP_BAD_INPUT);
    double cl[6] = {0, 0, 0, 0, 0, 0}, joints[5];
    expect("zero tool axis", pp_cl_to_joints(m, cl, 1, PP_BRANCH_NEAREST, joints), PP_BAD_INPUT);
    expect("bad branch rule", pp_cl_to_joints(m, cl, 1, 9, joints), PP_BAD_INPUT);
    pp_buffer_free(&junk_out);
    pp_machine_free(m);
    pp_machine_free(NULL);
    free(input);
    if (failures) {
        fprintf(stderr, "%d failure(s)\n", failures);
        return 1;
    }
    printf("ok (polepatch %s)\n", pp_version());
    return 0;
}
