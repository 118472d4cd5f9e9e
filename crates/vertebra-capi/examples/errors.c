/* The error paths from C: refused calls, their codes and messages, outputs
 * left alone, and every object freed (run under the address sanitizer, its
 * leak checker must stay quiet).
 *
 *   ./errors [crates/vertebra-ragdoll/models/humanoid.toml]
 *
 * Prints one line per check and "all refusals as documented" at the end;
 * exits 1 at the first surprise. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vertebra.h"

static int checks = 0;

/* `result` must be `expected`, with a message containing `word`. */
static void expect(const char *what, VtResult result, VtResult expected, const char *word) {
    const char *message = vt_last_error_message();
    if (result != expected || (word != NULL && strstr(message, word) == NULL)) {
        fprintf(stderr, "%s: %s (%s), expected %s naming `%s`\n", what,
                vt_result_name(result), message, vt_result_name(expected),
                word != NULL ? word : "");
        exit(1);
    }
    checks++;
    printf("%s: %s\n", what, vt_result_name(result));
}

#define OK(call) expect(#call, (call), VT_RESULT_OK, NULL)

int main(int argc, char **argv) {
    const float dt = 1.0f / 60.0f;
    VtWorld *world = NULL;
    VtCollisions *collisions = NULL;
    VtRagdollDesc *desc = NULL;
    OK(vt_world_create(NULL, &world));
    OK(vt_collisions_create(&collisions));
    if (argc > 1) {
        OK(vt_ragdoll_desc_from_file(argv[1], &desc));
    } else {
        OK(vt_ragdoll_desc_humanoid(VT_HUMANOID_REFERENCE, &desc));
    }

    /* Null pointers name the argument. */
    expect("step a null world", vt_world_step(NULL, dt), VT_RESULT_NULL_POINTER, "world");
    expect("hash into null", vt_world_state_hash(world, NULL), VT_RESULT_NULL_POINTER, "hash");

    /* A refused config writes no world. */
    VtSolverConfig config;
    OK(vt_solver_config_default(&config));
    config.substeps = 0;
    VtWorld *never = NULL;
    expect("zero substeps", vt_world_create(&config, &never), VT_RESULT_INVALID_CONFIG,
           "substeps");
    config.substeps = 1;
    config.backend = 99;
    expect("backend 99", vt_world_create(&config, &never), VT_RESULT_INVALID_ENUM,
           "config.backend");
    if (never != NULL) {
        fprintf(stderr, "a refused create wrote a world\n");
        return 1;
    }

    /* Bodies: a bad kind, NaN, a non-unit rotation; the handle is untouched. */
    VtBodyDesc body_desc;
    OK(vt_body_desc_default(VT_BODY_KIND_DYNAMIC, &body_desc));
    VtShape shape;
    memset(&shape, 0, sizeof shape);
    shape.kind = VT_SHAPE_KIND_SPHERE;
    shape.radius = 0.2f;
    OK(vt_shape_mass_properties(&shape, 3.0f, &body_desc.mass));
    body_desc.has_mass = 1;
    body_desc.position.y = 2.0f;
    VtBody body = {1234u, 5678u, 9u};
    body_desc.kind = 7;
    expect("body kind 7", vt_world_add_body(world, &body_desc, &body), VT_RESULT_INVALID_ENUM,
           "body.kind");
    body_desc.kind = VT_BODY_KIND_DYNAMIC;
    body_desc.position.x = NAN;
    expect("NaN position", vt_world_add_body(world, &body_desc, &body), VT_RESULT_NON_FINITE,
           "position");
    body_desc.position.x = 0.0f;
    if (body.index != 1234u || body.generation != 9u) {
        fprintf(stderr, "a refused add wrote the handle\n");
        return 1;
    }
    OK(vt_world_add_body(world, &body_desc, &body));
    uint64_t before = 0, after = 0;
    OK(vt_world_state_hash(world, &before));
    VtQuat half = {0.0f, 0.0f, 0.0f, 0.5f};
    expect("non-unit rotation", vt_world_set_body_pose(world, body, (VtVec3){0, 0, 0}, half),
           VT_RESULT_NOT_NORMALIZED, "orientation");
    expect("infinite impulse",
           vt_world_push(world, body, VT_PUSH_IMPULSE, (VtVec3){INFINITY, 0, 0}),
           VT_RESULT_NON_FINITE, "impulse");
    expect("negative dt", vt_world_step(world, -dt), VT_RESULT_NON_POSITIVE, "time step");
    OK(vt_world_state_hash(world, &after));
    if (before != after) {
        fprintf(stderr, "a refused call changed the world\n");
        return 1;
    }

    /* Handles: removed, then used. */
    OK(vt_world_remove_body(world, body));
    VtBodyState state;
    expect("a removed body", vt_world_body_state(world, body, &state), VT_RESULT_STALE_HANDLE,
           "body");
    VtBody made_up = {3u, 0xabcdu, 1u};
    expect("a made-up body", vt_world_wake(world, made_up), VT_RESULT_FOREIGN_HANDLE, "body");

    /* Text out: ask the length, then a buffer too small, then enough. */
    size_t length = 0;
    expect("ask the name's length", vt_ragdoll_desc_body_name(desc, 0, NULL, 0, &length),
           VT_RESULT_BUFFER_TOO_SMALL, NULL);
    char small[2] = {'#', '#'};
    expect("a name too long", vt_ragdoll_desc_body_name(desc, 0, small, sizeof small, &length),
           VT_RESULT_BUFFER_TOO_SMALL, NULL);
    if (small[0] != '#' || small[1] != '#') {
        fprintf(stderr, "a refused copy wrote the buffer\n");
        return 1;
    }
    char *name = malloc(length);
    if (name == NULL) {
        return 1;
    }
    OK(vt_ragdoll_desc_body_name(desc, 0, name, length, &length));
    printf("body 0 is %s\n", name);
    free(name);

    /* A broken description names its line; a pose of the wrong length. */
    VtRagdollDesc *broken = NULL;
    expect("broken TOML", vt_ragdoll_desc_from_string("name = \"x\"\n[[body]\n", &broken),
           VT_RESULT_RAGDOLL, "line 2");
    size_t count = 0;
    OK(vt_ragdoll_desc_body_count(desc, &count));
    VtTransform *pose = calloc(count, sizeof *pose);
    if (pose == NULL) {
        return 1;
    }
    OK(vt_ragdoll_desc_bind_pose(desc, pose, count));
    VtBuildOptions options = {VT_SPINE_MODE_ROD, 0, 0, 1.0f};
    VtRagdoll *ragdoll = NULL;
    expect("a short pose",
           vt_ragdoll_build(world, collisions, desc, &options, pose, NULL, count - 1, dt,
                            &ragdoll),
           VT_RESULT_RAGDOLL, NULL);
    pose[2].rotation.w = NAN;
    expect("a NaN pose",
           vt_ragdoll_build(world, collisions, desc, &options, pose, NULL, count, dt, &ragdoll),
           VT_RESULT_RAGDOLL, "spine_upper");
    pose[2].rotation.w = 1.0f;
    OK(vt_ragdoll_build(world, collisions, desc, &options, pose, NULL, count, dt, &ragdoll));
    free(pose);
    expect("an unknown body", vt_ragdoll_apply_impulse(ragdoll, world, "tail", (VtVec3){1, 0, 0}, NULL),
           VT_RESULT_RAGDOLL, "tail");
    uint32_t present = 7;
    expect("a body past the end", vt_ragdoll_body(ragdoll, count, &body, &present),
           VT_RESULT_OUT_OF_RANGE, NULL);
    OK(vt_collisions_update(collisions, world, dt));
    OK(vt_world_step(world, dt));

    /* Colliders start from vt_collider_default (a zeroed one collides
     * with nothing); one whose shape was forgotten is refused. */
    VtCollider collider;
    OK(vt_collider_default(body, &collider));
    expect("a collider without its shape", vt_collisions_add(collisions, &collider, NULL),
           VT_RESULT_COLLIDER, "radius");
    expect("a default collider into null", vt_collider_default(body, NULL),
           VT_RESULT_NULL_POINTER, "collider");

    /* Snapshots: damaged bytes are refused, the world kept. The layer's
     * snapshot is taken with the world's, and restored after it: until
     * then the layer refuses the restored world. */
    VtBytes *snapshot = NULL;
    VtBytes *layer_snapshot = NULL;
    OK(vt_world_snapshot(world, &snapshot));
    OK(vt_collisions_snapshot(collisions, world, &layer_snapshot));
    const uint8_t *data = NULL;
    size_t size = 0;
    const uint8_t *layer_data = NULL;
    size_t layer_size = 0;
    OK(vt_bytes_data(snapshot, &data, &size));
    OK(vt_bytes_data(layer_snapshot, &layer_data, &layer_size));
    OK(vt_world_state_hash(world, &before));
    expect("half a snapshot", vt_world_restore(world, data, size / 2),
           VT_RESULT_CORRUPT_SNAPSHOT, NULL);
    OK(vt_world_state_hash(world, &after));
    if (before != after) {
        fprintf(stderr, "a refused restore changed the world\n");
        return 1;
    }
    OK(vt_world_restore(world, data, size));
    expect("a world restored without its layer", vt_collisions_update(collisions, world, dt),
           VT_RESULT_WORLD_MISMATCH, "restored a snapshot");
    OK(vt_collisions_restore(collisions, world, layer_data, layer_size));
    OK(vt_collisions_update(collisions, world, dt));
    vt_bytes_destroy(snapshot);
    vt_bytes_destroy(layer_snapshot);

    /* The job system: no callback, too many workers. */
    VtTaskSystem tasks = {4u, NULL, NULL};
    expect("no parallel_for", vt_world_set_tasks(world, &tasks), VT_RESULT_NULL_POINTER,
           "tasks.parallel_for");

    OK(vt_ragdoll_remove(ragdoll, world, collisions));
    /* Its bodies are gone: what uses them is refused. */
    expect("a removed ragdoll's velocity",
           vt_ragdoll_set_velocity(ragdoll, world, (VtVec3){1, 0, 0}, (VtVec3){0, 0, 0}),
           VT_RESULT_STALE_HANDLE, "removed");

    vt_ragdoll_destroy(ragdoll);
    vt_collisions_destroy(collisions);
    vt_world_destroy(world);
    vt_ragdoll_desc_destroy(desc);
    /* Null does nothing. */
    vt_world_destroy(NULL);
    vt_bytes_destroy(NULL);
    printf("all %d refusals as documented\n", checks);
    return 0;
}
