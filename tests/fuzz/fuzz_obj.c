/* libFuzzer harness: ccn_obj_parse on arbitrary bytes (not NUL-terminated); when it parses,
 * ccn_obj_get_cage + ccn_mesh_create, and when that succeeds ccn_refine by 1 and 2 levels with
 * a scheme and corner rule picked from a hash of the input. Checks: statuses in range and
 * equal to err.status, messages NUL-terminated, refined counts, indices and positions
 * finite (fuzz_common.h). */
#include "fuzz_common.h"

static uint32_t hash(const uint8_t *d, size_t n) {
    uint32_t h = 2166136261u;
    for (size_t i = 0; i < n; i++) h = (h ^ d[i]) * 16777619u;
    return h;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size > 65536) return 0;
    ccn_error e;
    fz_err_init(&e);
    ccn_obj *obj = (ccn_obj *)&e;
    ccn_status st = ccn_obj_parse((const char *)data, size, &obj, &e);
    fz_check_status(st, &e, "ccn_obj_parse");
    if (st != CCN_OK) {
        FZ_CHECK(obj == NULL, "parse failed but returned an object");
        FZ_CHECK(st == CCN_ERR_IO || st == CCN_ERR_MEMORY, "parse status %d", (int)st);
        return 0;
    }
    FZ_CHECK(obj != NULL, "parse OK without an object");
    ccn_cage cage;
    FZ_CHECK(ccn_obj_get_cage(obj, &cage) == CCN_OK, "ccn_obj_get_cage");
    FZ_CHECK(cage.num_verts >= 0 && cage.num_faces >= 0 && cage.num_edges >= 0, "counts");
    ccn_mesh *m = NULL;
    if (fz_create_check(&cage, &m) == CCN_OK) {
        uint32_t h = hash(data, size);
        ccn_options o = {0};
        o.scheme = (ccn_scheme)(h % 3);
        o.boundary_corners = (int32_t)((h >> 2) & 1);
        ccn_mesh_info in;
        ccn_mesh_get_info(m, &in);
        int32_t max_face = 0;
        for (int32_t f = 0; f < cage.num_faces; f++)
            if (cage.face_sizes[f] > max_face) max_face = cage.face_sizes[f];
        fz_refine_check(m, 1, &o);
        /* two levels only while they stay cheap (a k-gon becomes a valence-k EV) */
        if (in.num_face_verts <= 4096 && in.max_valence <= 256 && max_face <= 256)
            fz_refine_check(m, 2, &o);
        ccn_mesh_destroy(m);
    }
    ccn_obj_destroy(obj);
    return 0;
}
