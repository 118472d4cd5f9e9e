//! What a glTF file holds of a run, gathered frame by frame: every body
//! with a shape and its pose each frame, and each ragdoll's reference
//! skeleton, bone by bone relative to its parent.

use glam::{Quat, Vec3};
use vertebra_collide::ColliderShape;
use vertebra_ragdoll::{RagdollError, Transform};
use vertebra_scenes::{SceneWorld, SkeletonOut};
use vertebra_world::{BodyHandle, Shape};

/// A body's geometry in its body frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solid {
    /// A sphere, box or capsule.
    Shape(Shape),
    /// A ground plane through the body's origin, with this unit normal.
    Plane(Vec3),
}

/// One body with a shape, and its pose (position of its centre of mass,
/// m, world; orientation) after each frame.
pub struct Body {
    /// The description's name for a ragdoll's body, else `ground` or
    /// `static K`.
    pub name: String,
    /// Its geometry.
    pub solid: Solid,
    /// The ragdoll it belongs to, by index, if any.
    pub ragdoll: Option<usize>,
    /// Per frame.
    pub poses: Vec<(Vec3, Quat)>,
    handle: BodyHandle,
}

/// Every frame's pose of every bone of each ragdoll's reference skeleton.
pub struct Skeletons {
    /// The mappers, and the skeleton with its bind pose.
    pub out: SkeletonOut,
    /// Per ragdoll, per bone, per frame: the bone's transform relative to
    /// its parent bone (a root's: in the world).
    pub locals: Vec<Vec<Vec<Transform>>>,
}

/// A run as gathered so far.
pub struct Recording {
    /// The bodies with a shape: each ragdoll's in order, then the rest.
    pub bodies: Vec<Body>,
    /// The skeletons, or `None` if the scene's ragdolls do not map onto
    /// the reference skeleton (the heavy chain), and why.
    pub skeletons: Result<Skeletons, String>,
    /// Frames gathered.
    pub frames: usize,
    /// Ragdolls in the scene.
    pub ragdolls: usize,
}

impl Recording {
    /// The bodies of `scene` that have a shape (each ragdoll's, then the
    /// colliders on other bodies: ground, walls, boxes), and the mappers
    /// onto the reference skeleton where the ragdolls map; nothing yet
    /// recorded.
    pub fn new(scene: &SceneWorld) -> Self {
        let mut bodies = Vec::new();
        for (k, ragdoll) in scene.ragdolls.iter().enumerate() {
            let defs = &ragdoll.description().bodies;
            for (def, handle) in defs.iter().zip(&ragdoll.bodies) {
                if let Some(handle) = *handle {
                    bodies.push(Body::new(
                        def.name.clone(),
                        Solid::Shape(def.shape()),
                        Some(k),
                        handle,
                    ));
                }
            }
        }
        let colliders = scene.collisions.iter().flat_map(|c| c.colliders());
        let mut statics = 0;
        for collider in colliders {
            if bodies.iter().any(|b| b.handle == collider.body) {
                continue;
            }
            let (name, solid) = match collider.shape {
                ColliderShape::Plane(normal) => ("ground".to_owned(), Solid::Plane(normal)),
                ColliderShape::Solid(shape) => {
                    statics += 1;
                    (format!("static {statics}"), Solid::Shape(shape))
                }
            };
            bodies.push(Body::new(name, solid, None, collider.body));
        }
        let skeletons = SkeletonOut::new(scene)
            .map(|out| Skeletons {
                locals: vec![vec![Vec::new(); out.skeleton().len()]; scene.ragdolls.len()],
                out,
            })
            .map_err(|e| e.to_string());
        Self {
            bodies,
            skeletons,
            frames: 0,
            ragdolls: scene.ragdolls.len(),
        }
    }

    /// Gathers `scene` as it is now: one more frame.
    pub fn record(&mut self, scene: &SceneWorld) -> Result<(), RagdollError> {
        for body in &mut self.bodies {
            let state = scene.world.body(body.handle)?;
            body.poses.push((state.position, state.orientation));
        }
        if let Ok(skeletons) = &mut self.skeletons {
            let skeleton = skeletons.out.skeleton();
            for (pose, ragdoll) in skeletons
                .out
                .poses(scene)?
                .iter()
                .zip(&mut skeletons.locals)
            {
                let local = pose.to_local(skeleton)?;
                for (bone, t) in ragdoll.iter_mut().zip(local.bones) {
                    bone.push(t);
                }
            }
        }
        self.frames += 1;
        Ok(())
    }
}

impl Body {
    fn new(name: String, solid: Solid, ragdoll: Option<usize>, handle: BodyHandle) -> Self {
        Self {
            name,
            solid,
            ragdoll,
            poses: Vec::new(),
            handle,
        }
    }
}
