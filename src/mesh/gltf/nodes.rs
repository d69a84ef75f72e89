//! The node hierarchy: every node's rest transform (translation, rotation, scale) and morph
//! weights, posed at a time by the channels and composed parent before child into world transforms.

use super::channels::Channel;
use gltf::animation::Property;
use nalgebra::{Matrix4, Quaternion, UnitQuaternion, Vector3};

/// Node transforms and morph weights at rest, posed at any time by the channels.
pub(super) struct Pose {
    rest: Vec<Trs>,
    rest_weights: Vec<Vec<f64>>,
    /// Parents before children, so world transforms can be built in one pass.
    order: Vec<usize>,
    parent: Vec<Option<usize>>,
}

/// World transforms and morph weights of every node at one time.
pub(super) struct Posed {
    pub(super) world: Vec<Matrix4<f64>>,
    pub(super) weights: Vec<Vec<f64>>,
}

impl Posed {
    /// The world transform of `node` (identity for a node that does not exist).
    pub(super) fn world_of(&self, node: usize) -> Matrix4<f64> {
        self.world
            .get(node)
            .copied()
            .unwrap_or_else(Matrix4::identity)
    }
}

#[derive(Debug, Clone)]
struct Trs {
    translation: Vector3<f64>,
    rotation: UnitQuaternion<f64>,
    scale: Vector3<f64>,
}

impl Trs {
    fn matrix(&self) -> Matrix4<f64> {
        Matrix4::new_translation(&self.translation)
            * self.rotation.to_homogeneous()
            * Matrix4::new_nonuniform_scaling(&self.scale)
    }
}

impl Pose {
    pub(super) fn new(document: &gltf::Document) -> Self {
        let rest = document
            .nodes()
            .map(|n| {
                let (t, r, s) = n.transform().decomposed();
                Trs {
                    translation: Vector3::new(t[0], t[1], t[2]).cast(),
                    rotation: UnitQuaternion::new_normalize(
                        Quaternion::new(r[3], r[0], r[1], r[2]).cast(),
                    ),
                    scale: Vector3::new(s[0], s[1], s[2]).cast(),
                }
            })
            .collect();
        let rest_weights = document
            .nodes()
            .map(|n| {
                let w = n.weights().or_else(|| n.mesh().and_then(|m| m.weights()));
                w.unwrap_or(&[]).iter().map(|&x| x as f64).collect()
            })
            .collect();
        let (order, parent) = hierarchy(document);
        Self {
            rest,
            rest_weights,
            order,
            parent,
        }
    }

    /// World transforms and morph weights at `time`.
    pub(super) fn at(&self, time: f64, channels: &[Channel]) -> Posed {
        let mut local = self.rest.clone();
        let mut weights = self.rest_weights.clone();
        for c in channels {
            let (Some(trs), Some(w)) = (local.get_mut(c.node), weights.get_mut(c.node)) else {
                continue;
            };
            let v = c.sample(time);
            match c.property {
                Property::Translation => trs.translation = Vector3::new(v[0], v[1], v[2]),
                Property::Scale => trs.scale = Vector3::new(v[0], v[1], v[2]),
                Property::Rotation => {
                    trs.rotation =
                        UnitQuaternion::new_normalize(Quaternion::new(v[3], v[0], v[1], v[2]))
                }
                Property::MorphTargetWeights => *w = v,
            }
        }
        let mut world = vec![Matrix4::identity(); local.len()];
        for &n in &self.order {
            let own = local[n].matrix();
            world[n] = match self.parent[n] {
                Some(p) => world[p] * own,
                None => own,
            };
        }
        Posed { world, weights }
    }
}

/// Every node's parent, and the nodes in an order that puts parents before children (depth first
/// from the roots; a node reached twice is visited once).
fn hierarchy(document: &gltf::Document) -> (Vec<usize>, Vec<Option<usize>>) {
    let count = document.nodes().count();
    let mut parent = vec![None; count];
    for node in document.nodes() {
        for child in node.children() {
            parent[child.index()] = Some(node.index());
        }
    }
    let children: Vec<Vec<usize>> = document
        .nodes()
        .map(|n| n.children().map(|c| c.index()).collect())
        .collect();
    let mut order = Vec::with_capacity(count);
    let mut seen = vec![false; count];
    let mut stack: Vec<usize> = (0..count).filter(|&n| parent[n].is_none()).rev().collect();
    while let Some(n) = stack.pop() {
        if std::mem::replace(&mut seen[n], true) {
            continue;
        }
        order.push(n);
        stack.extend(children[n].iter().rev());
    }
    (order, parent)
}
