//! Animated triangle meshes: one connectivity shared by all frames, one position set per frame.
//!
//! [`AnimatedMesh`] is what every stage works on. [`read_animation`] reads OBJ sequences (a folder
//! or glob), PC2 point caches with their base OBJ, and glTF/GLB morph-target or skinned clips
//! (baked at a frame rate); [`FrameSource`] reads a long one a run of frames at a time. The
//! writers give OBJ frames, PC2 caches and glTF with a morph target per frame.

mod attributes;
#[cfg(feature = "encode")]
mod summary;
pub(crate) mod vector;
internal! {
    #[cfg(feature = "encode")]
    frames;
    #[cfg(feature = "encode")]
    gltf_write;
    #[cfg(feature = "encode")]
    io;
    topology;
}

#[cfg(feature = "encode")]
mod gltf;
#[cfg(feature = "encode")]
mod obj;
#[cfg(feature = "encode")]
mod obj_files;
#[cfg(feature = "encode")]
mod obj_skeleton;
#[cfg(feature = "encode")]
mod pc2;

pub use attributes::Attributes;
#[cfg(feature = "encode")]
pub use frames::FrameSource;

/// Frames per second of a glTF output when the source's rate is unknown (OBJ and PC2 inputs).
pub const DEFAULT_FPS: f64 = 30.0;
#[cfg(feature = "encode")]
pub use gltf::Clip;
#[cfg(feature = "encode")]
pub use gltf_write::{is_gltf_path, write_gltf, GltfOptions, MANY_MORPH_TARGETS};
#[cfg(feature = "encode")]
pub use io::{
    clips, input_files, obj_frame_names, parse_gltf, parse_obj, parse_pc2, read_animation,
    write_obj_frame, write_obj_mesh_frame, write_obj_sequence, write_obj_sequence_from, write_pc2,
    ObjFrameWriter, Pc2Writer, ReadOptions,
};
#[cfg(feature = "encode")]
pub use summary::Summary;

use crate::error::{Error, Result};

/// A 3D position.
pub type Point = [f32; 3];

/// Largest coordinate magnitude [`AnimatedMesh::new`] accepts. Segmentation squares and sums
/// position differences in f32, and a coordinate of 1e25 made k-means++'s total seed weight
/// infinite (a panic in the sampler); beyond this the codecs cannot code the motion anyway
/// (f32 keeps about 7 digits: at 1e15 neighbouring values are 1e8 apart), so such input is refused
/// up front with the vertex named.
pub const MAX_COORDINATE: f32 = 1e15;

/// A key equal for two positions exactly when their coordinates are equal (the bits, with −0
/// and +0 one key), for welding vertices that share a position.
pub(crate) fn position_key(p: &Point) -> [u32; 3] {
    p.map(|c| if c == 0.0 { 0 } else { c.to_bits() })
}

/// A triangle: three vertex indices.
pub type Triangle = [u32; 3];

/// An animated mesh: triangles shared by all frames and `F` frames of `V` positions.
///
/// Invariants (checked by [`AnimatedMesh::new`]): at least one frame and one vertex, every frame has
/// the same number of vertices, every index is in range, every coordinate is finite and at most
/// [`MAX_COORDINATE`] in magnitude.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimatedMesh {
    triangles: Vec<Triangle>,
    frames: Vec<Vec<Point>>,
    attributes: Attributes,
    frame_rate: Option<f64>,
}

impl AnimatedMesh {
    /// Builds an animated mesh, checking the invariants; the error names the offending frame or face.
    pub fn new(triangles: Vec<Triangle>, frames: Vec<Vec<Point>>) -> Result<Self> {
        let first = frames
            .first()
            .ok_or_else(|| Error::Mesh("the animation has no frames".into()))?;
        let v = first.len();
        if v == 0 {
            return Err(Error::Mesh("the mesh has no vertices".into()));
        }
        if v > u32::MAX as usize {
            return Err(Error::Mesh(format!(
                "{v} vertices is more than this tool can index"
            )));
        }
        for (f, frame) in frames.iter().enumerate() {
            if frame.len() != v {
                return Err(Error::Mesh(format!(
                    "frame {f} has {} vertices but frame 0 has {v}",
                    frame.len()
                )));
            }
            // One pass over the coordinates (NaN fails the comparison too); a frame with a
            // coordinate out of bounds names its first non-finite one if any, else the first
            // beyond the bound.
            let within = |p: &Point| p.iter().all(|c| c.abs() <= MAX_COORDINATE);
            if let Some(beyond) = frame.iter().position(|p| !within(p)) {
                let not_finite = |p: &Point| p.iter().any(|c| !c.is_finite());
                if let Some(i) = frame[beyond..].iter().position(not_finite) {
                    return Err(Error::Mesh(format!(
                        "frame {f}, vertex {}: coordinate is not a finite number",
                        beyond + i
                    )));
                }
                let p = frame[beyond];
                return Err(Error::Mesh(format!(
                    "frame {f}, vertex {beyond}: coordinate ({} {} {}) is beyond \
                     ±{MAX_COORDINATE:e}, the largest this tool handles",
                    p[0], p[1], p[2]
                )));
            }
        }
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= v) {
                return Err(Error::Mesh(format!(
                    "face {t} refers to vertex {bad}, but the mesh has {v} vertices"
                )));
            }
        }
        Ok(Self {
            triangles,
            frames,
            attributes: Attributes::default(),
            frame_rate: None,
        })
    }

    /// The same mesh with its source's frame rate (frames per second; not finite or not positive:
    /// unknown). glTF inputs know theirs; the stream keeps it, so glTF output plays at that rate.
    pub fn with_frame_rate(mut self, fps: Option<f64>) -> Self {
        self.frame_rate = fps.filter(|r| r.is_finite() && *r > 0.0);
        self
    }

    /// The source's frames per second, when known.
    pub fn frame_rate(&self) -> Option<f64> {
        self.frame_rate
    }

    /// The same mesh with texture coordinates and materials (checked against its vertices and
    /// triangles).
    pub fn with_attributes(mut self, attributes: Attributes) -> Result<Self> {
        attributes.check(self.vertex_count(), self.triangles.len())?;
        self.attributes = attributes;
        Ok(self)
    }

    /// Texture coordinates and materials (empty for inputs that have none).
    pub fn attributes(&self) -> &Attributes {
        &self.attributes
    }

    /// The triangles, shared by every frame.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// All frames, each `V` positions.
    pub fn frames(&self) -> &[Vec<Point>] {
        &self.frames
    }

    /// Frames `range` as an animation of their own, with the same connectivity, attributes and
    /// frame rate (an empty or out-of-bounds range is an error).
    pub fn clip(&self, range: std::ops::Range<usize>) -> Result<Self> {
        match self.frames.get(range.clone()) {
            Some(frames) if !frames.is_empty() => Ok(Self {
                triangles: self.triangles.clone(),
                frames: frames.to_vec(),
                attributes: self.attributes.clone(),
                frame_rate: self.frame_rate,
            }),
            _ => Err(Error::Usage(format!(
                "frames {range:?}: the animation has {}",
                self.frames.len()
            ))),
        }
    }

    /// The positions of frame `f` (panics if `f` is out of range: callers index with `0..frame_count()`).
    pub fn frame(&self, f: usize) -> &[Point] {
        &self.frames[f]
    }

    /// Number of vertices `V`.
    pub fn vertex_count(&self) -> usize {
        self.frames[0].len()
    }

    /// Number of frames `F`.
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Consumes the mesh, giving back triangles and frames.
    pub fn into_parts(self) -> (Vec<Triangle>, Vec<Vec<Point>>) {
        (self.triangles, self.frames)
    }

    /// Length of the diagonal of frame 0's axis-aligned bounding box: the unit every error is measured in.
    pub fn bbox_diagonal(&self) -> f64 {
        bbox_diagonal(&self.frames[0])
    }
}

/// The diagonal of a point set's axis-aligned bounding box (0 for an empty set).
pub fn bbox_diagonal(points: &[Point]) -> f64 {
    let (lo, hi) = bounding_box(points);
    let d: f64 = (0..3).map(|a| (hi[a] - lo[a]) as f64).map(|x| x * x).sum();
    d.sqrt()
}

/// The axis-aligned bounding box `(min, max)` of a point set; `([0;3],[0;3])` for an empty set.
pub fn bounding_box(points: &[Point]) -> (Point, Point) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    if points.is_empty() {
        ([0.0; 3], [0.0; 3])
    } else {
        (lo, hi)
    }
}

impl AnimatedMesh {
    /// The same animation with vertices renumbered: new vertex `i` is old vertex `order[i]`.
    pub fn permuted(&self, order: &[u32]) -> Result<Self> {
        let v = self.vertex_count();
        let mut new_index = vec![u32::MAX; v];
        if order.len() != v {
            return Err(Error::Mesh(format!(
                "a permutation of {} entries for {v} vertices",
                order.len()
            )));
        }
        for (i, &old) in order.iter().enumerate() {
            match new_index.get_mut(old as usize) {
                Some(slot) if *slot == u32::MAX => *slot = i as u32,
                _ => return Err(Error::Mesh("vertex order is not a permutation".into())),
            }
        }
        let triangles = self
            .triangles
            .iter()
            .map(|t| t.map(|i| new_index[i as usize]))
            .collect();
        let frames = self
            .frames
            .iter()
            .map(|f| order.iter().map(|&old| f[old as usize]).collect())
            .collect();
        let mut attributes = self.attributes.clone();
        for set in &mut attributes.texcoords {
            *set = order.iter().map(|&old| set[old as usize]).collect();
        }
        Ok(Self {
            triangles,
            frames,
            attributes,
            frame_rate: self.frame_rate,
        })
    }
}
