//! Animations read a run of frames at a time: OBJ sequences file by file and PC2
//! caches sample by sample, so that a long clip is never held whole. glTF clips are baked whole
//! (the baker poses every frame from the clip's channels) and served from memory.

use super::obj::{read_frames, read_obj};
use super::obj_files::frame_files;
use super::obj_skeleton::FirstObj;
use super::{gltf, pc2, AnimatedMesh, Point, ReadOptions};
use crate::error::{Error, Result};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// An animation whose frames are read on request, in any order.
pub struct FrameSource {
    /// The first frame, with the connectivity, attributes and frame rate every run shares.
    first: AnimatedMesh,
    frames: usize,
    origin: Origin,
}

/// Where the frames come from.
enum Origin {
    /// One OBJ file per frame (the first one's connectivity checked in each), and frames read
    /// once already that a later read will ask for again ([`FrameSource::read_list_keeping`]):
    /// parsing an OBJ file costs far more than holding its positions (a tenth of a default
    /// encode of a 7 000-vertex OBJ clip went to parsing its analysis frames a second time).
    Obj {
        files: Vec<PathBuf>,
        kept: HashMap<usize, Vec<Point>>,
        first: FirstObj,
    },
    /// A PC2 cache: `points` positions of 12 bytes per sample.
    Pc2 {
        file: File,
        path: PathBuf,
        points: usize,
    },
    /// Frames already in memory (glTF bakes).
    Memory(AnimatedMesh),
}

impl FrameSource {
    /// Opens an animation as [`super::read_animation`] names it, reading its first frame only
    /// (all of it for glTF).
    pub fn open(input: &str, opts: &ReadOptions) -> Result<Self> {
        let path = Path::new(input);
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        super::io::check_clip(input, extension.as_deref(), opts)?;
        match extension.as_deref() {
            Some("pc2") => Self::open_pc2(path, opts.base.as_deref()),
            Some("gltf") | Some("glb") => {
                let clip = opts.clip.as_deref();
                Self::from_mesh(gltf::read_gltf(path, opts.fps, clip, opts.max_positions)?)
            }
            _ => Self::open_obj(frame_files(input)?),
        }
    }

    /// A source over an animation in memory.
    pub fn from_mesh(mesh: AnimatedMesh) -> Result<Self> {
        Ok(Self {
            frames: mesh.frame_count(),
            first: mesh.clip(0..1)?,
            origin: Origin::Memory(mesh),
        })
    }

    fn open_obj(files: Vec<PathBuf>) -> Result<Self> {
        let path = files
            .first()
            .ok_or_else(|| Error::Usage("no .obj files to read".into()))?;
        let (frame, first_obj) = FirstObj::read(path)?;
        let first = AnimatedMesh::new(frame.triangles, vec![frame.positions])?
            .with_attributes(frame.attributes)?;
        Ok(Self {
            frames: files.len(),
            first,
            origin: Origin::Obj {
                files,
                kept: HashMap::new(),
                first: first_obj,
            },
        })
    }

    fn open_pc2(path: &Path, base: Option<&Path>) -> Result<Self> {
        let mesh_error = |what: String| Error::Mesh(format!("{}: {what}", path.display()));
        let mut file = File::open(path).map_err(|e| Error::io(path, e))?;
        let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
        let mut header = Vec::new();
        (&mut file)
            .take(pc2::SAMPLES_START)
            .read_to_end(&mut header)
            .map_err(|e| Error::io(path, e))?;
        let (points, samples) = pc2::parse_header(&header, len).map_err(mesh_error)?;
        let base = pc2::base_path(path, base)?;
        let obj = read_obj(&base)?;
        pc2::check_base(points, &obj, path, &base)?;
        let mut source = Self {
            frames: samples,
            first: AnimatedMesh::new(obj.triangles, vec![obj.positions])?
                .with_attributes(obj.attributes)?,
            origin: Origin::Pc2 {
                file,
                path: path.to_path_buf(),
                points,
            },
        };
        // The cache's own first sample is the first frame (the base OBJ gives faces only).
        let first = source.read(0..1)?;
        source.first = AnimatedMesh::new(source.first.triangles().to_vec(), first)?
            .with_attributes(source.first.attributes().clone())?;
        Ok(source)
    }

    /// Frames in the animation.
    pub fn frame_count(&self) -> usize {
        self.frames
    }

    /// The first frame as a one-frame animation (connectivity, attributes, frame rate).
    pub fn first(&self) -> &AnimatedMesh {
        &self.first
    }

    /// The positions of `frames`.
    pub fn read(&mut self, frames: Range<usize>) -> Result<Vec<Vec<Point>>> {
        if frames.start > frames.end || frames.end > self.frames {
            return Err(Error::Usage(format!(
                "frames {frames:?}: the animation has {}",
                self.frames
            )));
        }
        self.read_list(&frames.collect::<Vec<_>>())
    }

    /// The positions of the frames `list` names, in its order (OBJ files read on rayon's threads).
    pub fn read_list(&mut self, list: &[usize]) -> Result<Vec<Vec<Point>>> {
        self.read_frames(list, false)
    }

    /// [`FrameSource::read_list`], keeping a copy of each frame read from an OBJ file for the
    /// next read that asks for it (which takes it): for frames read twice, as a segmented
    /// encode's analysis clip's are (once spread, once in their segment). PC2 samples and frames
    /// in memory cost nothing to read again and are not kept.
    pub fn read_list_keeping(&mut self, list: &[usize]) -> Result<Vec<Vec<Point>>> {
        self.read_frames(list, true)
    }

    fn read_frames(&mut self, list: &[usize], keep: bool) -> Result<Vec<Vec<Point>>> {
        if let Some(f) = list.iter().find(|&&f| f >= self.frames) {
            return Err(Error::Usage(format!(
                "frame {f}: the animation has {}",
                self.frames
            )));
        }
        match &mut self.origin {
            Origin::Memory(mesh) => Ok(list.iter().map(|&f| mesh.frame(f).to_vec()).collect()),
            Origin::Obj { files, kept, first } => {
                let mut missing: Vec<usize> =
                    list.iter().copied().filter(|f| !kept.contains_key(f)).collect();
                missing.sort_unstable();
                missing.dedup();
                let chosen: Vec<PathBuf> = missing.iter().map(|&f| files[f].clone()).collect();
                let read = read_frames(&chosen, |path| first.read_later(path))?;
                let mut fresh: HashMap<usize, Vec<Point>> = missing.into_iter().zip(read).collect();
                // Every frame of `list` is fresh or kept.
                let out = (list.iter())
                    .map(|f| fresh.get(f).or_else(|| kept.get(f)).cloned().unwrap_or_default())
                    .collect();
                match keep {
                    true => kept.extend(fresh.drain()),
                    false => list.iter().for_each(|f| drop(kept.remove(f))),
                }
                Ok(out)
            }
            Origin::Pc2 { file, path, points } => {
                let bytes = *points as u64 * 12;
                let io = |e| Error::io(path.as_path(), e);
                let mut buf = vec![0u8; *points * 12];
                let mut next = None;
                let mut frames = Vec::with_capacity(list.len());
                for &f in list {
                    // Consecutive frames read on without seeking.
                    if next != Some(f) {
                        let at = pc2::SAMPLES_START + f as u64 * bytes;
                        file.seek(SeekFrom::Start(at)).map_err(io)?;
                    }
                    file.read_exact(&mut buf).map_err(io)?;
                    frames.push(pc2::parse_frame(&buf));
                    next = Some(f + 1);
                }
                Ok(frames)
            }
        }
    }

    /// Frames `frames` as an animation with the first frame's connectivity, attributes and rate.
    pub fn clip(&mut self, frames: Range<usize>) -> Result<AnimatedMesh> {
        let positions = self.read(frames)?;
        Ok(
            AnimatedMesh::new(self.first.triangles().to_vec(), positions)?
                .with_attributes(self.first.attributes().clone())?
                .with_frame_rate(self.first.frame_rate()),
        )
    }
}
