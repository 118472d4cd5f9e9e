/* Loads the humanoid, drops it on a ground plane and prints its hips each
 * second (and the world's state hash at the end).
 *
 *   cc -I crates/vertebra-capi/include crates/vertebra-capi/examples/drop.c \
 *      target/release/libvertebra_capi.a -lpthread -ldl -lm -o drop
 *   ./drop crates/vertebra-ragdoll/models/humanoid.toml
 *
 * Every call returns a VtResult; CHECK prints the reason and stops. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vertebra.h"

#define CHECK(call)                                                         \
    do {                                                                    \
        VtResult result_ = (call);                                          \
        if (result_ != VT_RESULT_OK) {                                      \
            fprintf(stderr, "%s failed: %s: %s\n", #call,                   \
                    vt_result_name(result_), vt_last_error_message());      \
            exit(1);                                                        \
        }                                                                   \
    } while (0)

static uint32_t bits(float x) {
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

int main(int argc, char **argv) {
    const float dt = 1.0f / 60.0f;

    /* The humanoid, from its file (or the shipped copy without one). */
    VtRagdollDesc *desc = NULL;
    if (argc > 1) {
        CHECK(vt_ragdoll_desc_from_file(argv[1], &desc));
    } else {
        CHECK(vt_ragdoll_desc_humanoid(VT_HUMANOID_REFERENCE, &desc));
    }

    /* A world with the default settings, and its collision layer. */
    VtWorld *world = NULL;
    VtCollisions *collisions = NULL;
    CHECK(vt_world_create(NULL, &world));
    CHECK(vt_collisions_create(&collisions));

    /* The ground: a static body with a plane collider, normal +y. */
    VtBodyDesc ground_desc;
    VtBody ground;
    CHECK(vt_body_desc_default(VT_BODY_KIND_STATIC, &ground_desc));
    CHECK(vt_world_add_body(world, &ground_desc, &ground));
    /* Every collider starts from vt_collider_default (every group,
     * friction 0.6): a zeroed one is in no group and collides with
     * nothing. */
    VtCollider plane;
    CHECK(vt_collider_default(ground, &plane));
    plane.kind = VT_COLLIDER_KIND_PLANE;
    plane.plane_normal = (VtVec3){0.0f, 1.0f, 0.0f};
    CHECK(vt_collisions_add(collisions, &plane, NULL));

    /* The ragdoll at its bind pose, half a metre up, with a rod spine,
     * tumbling forward. */
    size_t count = 0;
    CHECK(vt_ragdoll_desc_body_count(desc, &count));
    VtTransform *pose = malloc(count * sizeof *pose);
    if (pose == NULL) {
        return 1;
    }
    CHECK(vt_ragdoll_desc_bind_pose(desc, pose, count));
    for (size_t i = 0; i < count; i++) {
        pose[i].position.y += 0.5f;
    }
    VtBuildOptions options = {VT_SPINE_MODE_ROD, 0, 0, 1.0f};
    VtRagdoll *ragdoll = NULL;
    CHECK(vt_ragdoll_build(world, collisions, desc, &options, pose, NULL, count, dt, &ragdoll));
    CHECK(vt_ragdoll_set_velocity(ragdoll, world, (VtVec3){0.0f, 0.0f, 0.5f},
                                  (VtVec3){2.0f, 0.0f, 0.0f}));
    free(pose);

    size_t hips_index = 0;
    uint32_t present = 0;
    VtBody hips;
    CHECK(vt_ragdoll_desc_body_index(desc, "hips", &hips_index));
    CHECK(vt_ragdoll_body(ragdoll, hips_index, &hips, &present));

    for (int frame = 1; frame <= 4 * 60; frame++) {
        CHECK(vt_collisions_update(collisions, world, dt));
        CHECK(vt_world_step(world, dt));
        if (frame % 60 == 0) {
            VtBodyState state;
            CHECK(vt_world_body_state(world, hips, &state));
            VtVec3 p = state.position;
            printf("t=%d s hips %.6f %.6f %.6f [%08x %08x %08x]\n", frame / 60, p.x, p.y,
                   p.z, bits(p.x), bits(p.y), bits(p.z));
        }
    }
    uint64_t hash = 0;
    CHECK(vt_world_state_hash(world, &hash));
    printf("state hash %016llx\n", (unsigned long long)hash);

    vt_ragdoll_destroy(ragdoll);
    vt_collisions_destroy(collisions);
    vt_world_destroy(world);
    vt_ragdoll_desc_destroy(desc);
    return 0;
}
