// The C example in C++: the same scene through the same C ABI, with each
// object owned by a std::unique_ptr (its destroy as the deleter) and a
// refusal thrown as an exception carrying vertebra's message.
//
//   c++ -std=c++17 -I crates/vertebra-capi/include -o drop_cpp
//       crates/vertebra-capi/examples/drop.cpp target/release/libvertebra_capi.a
//       -lpthread -ldl -lm
//   ./drop_cpp crates/vertebra-ragdoll/models/humanoid.toml
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "vertebra.h"

namespace {

// Throws vertebra's reason for a refused call.
void check(VtResult result, const char *call) {
    if (result != VT_RESULT_OK) {
        throw std::runtime_error(std::string(call) + " failed: " + vt_result_name(result) +
                                 ": " + vt_last_error_message());
    }
}
#define CHECK(call) check((call), #call)

template <typename T, void (*destroy)(T *)> struct Deleter {
    void operator()(T *object) const { destroy(object); }
};
using World = std::unique_ptr<VtWorld, Deleter<VtWorld, vt_world_destroy>>;
using Collisions = std::unique_ptr<VtCollisions, Deleter<VtCollisions, vt_collisions_destroy>>;
using Desc = std::unique_ptr<VtRagdollDesc, Deleter<VtRagdollDesc, vt_ragdoll_desc_destroy>>;
using Ragdoll = std::unique_ptr<VtRagdoll, Deleter<VtRagdoll, vt_ragdoll_destroy>>;

uint32_t bits(float x) {
    uint32_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
}

void run(const char *path) {
    const float dt = 1.0f / 60.0f;
    VtRagdollDesc *made_desc = nullptr;
    if (path != nullptr) {
        CHECK(vt_ragdoll_desc_from_file(path, &made_desc));
    } else {
        CHECK(vt_ragdoll_desc_humanoid(VT_HUMANOID_REFERENCE, &made_desc));
    }
    Desc desc(made_desc);

    VtWorld *made_world = nullptr;
    CHECK(vt_world_create(nullptr, &made_world));
    World world(made_world);
    VtCollisions *made_collisions = nullptr;
    CHECK(vt_collisions_create(&made_collisions));
    Collisions collisions(made_collisions);

    VtBodyDesc ground_desc;
    VtBody ground;
    CHECK(vt_body_desc_default(VT_BODY_KIND_STATIC, &ground_desc));
    CHECK(vt_world_add_body(world.get(), &ground_desc, &ground));
    // Every collider starts from vt_collider_default (every group,
    // friction 0.6): a value-initialised one is in no group and collides
    // with nothing.
    VtCollider plane;
    CHECK(vt_collider_default(ground, &plane));
    plane.kind = VT_COLLIDER_KIND_PLANE;
    plane.plane_normal = VtVec3{0.0f, 1.0f, 0.0f};
    CHECK(vt_collisions_add(collisions.get(), &plane, nullptr));

    size_t count = 0;
    CHECK(vt_ragdoll_desc_body_count(desc.get(), &count));
    std::vector<VtTransform> pose(count);
    CHECK(vt_ragdoll_desc_bind_pose(desc.get(), pose.data(), pose.size()));
    for (VtTransform &body : pose) {
        body.position.y += 0.5f;
    }
    VtBuildOptions options{VT_SPINE_MODE_ROD, 0, 0, 1.0f};
    VtRagdoll *made_ragdoll = nullptr;
    CHECK(vt_ragdoll_build(world.get(), collisions.get(), desc.get(), &options, pose.data(),
                           nullptr, pose.size(), dt, &made_ragdoll));
    Ragdoll ragdoll(made_ragdoll);
    CHECK(vt_ragdoll_set_velocity(ragdoll.get(), world.get(), VtVec3{0.0f, 0.0f, 0.5f},
                                  VtVec3{2.0f, 0.0f, 0.0f}));

    size_t hips_index = 0;
    uint32_t present = 0;
    VtBody hips{};
    CHECK(vt_ragdoll_desc_body_index(desc.get(), "hips", &hips_index));
    CHECK(vt_ragdoll_body(ragdoll.get(), hips_index, &hips, &present));

    for (int frame = 1; frame <= 4 * 60; frame++) {
        CHECK(vt_collisions_update(collisions.get(), world.get(), dt));
        CHECK(vt_world_step(world.get(), dt));
        if (frame % 60 == 0) {
            VtBodyState state;
            CHECK(vt_world_body_state(world.get(), hips, &state));
            const VtVec3 p = state.position;
            std::printf("t=%d s hips %.6f %.6f %.6f [%08x %08x %08x]\n", frame / 60, p.x, p.y,
                        p.z, bits(p.x), bits(p.y), bits(p.z));
        }
    }
    uint64_t hash = 0;
    CHECK(vt_world_state_hash(world.get(), &hash));
    std::printf("state hash %016llx\n", static_cast<unsigned long long>(hash));
}

} // namespace

int main(int argc, char **argv) {
    try {
        run(argc > 1 ? argv[1] : nullptr);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
