//! Mesh files: binary STL, binary PLY with normals and colours, and OBJ,
//! each written atomically (a reader never sees half a file).

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use glam::Vec3;

use super::Mesh;
use crate::error::{Error, Result};
use crate::output::write_atomic;

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum MeshFormat {
    /// Binary STL: triangles with face normals, what 3D printers take.
    Stl,
    /// Binary little-endian PLY with vertex normals and colours.
    Ply,
    /// Wavefront OBJ with vertex normals and colours (`v x y z r g b`).
    Obj,
}

impl MeshFormat {
    /// The format a file name's extension names (`.stl`, `.ply`, `.obj`,
    /// in any case).
    ///
    /// # Errors
    /// [`Error::Invalid`] for any other extension.
    pub fn from_path(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("stl") => Ok(MeshFormat::Stl),
            Some("ply") => Ok(MeshFormat::Ply),
            Some("obj") => Ok(MeshFormat::Obj),
            _ => Err(Error::Invalid {
                what: "mesh file name",
                reason: format!(
                    "{}: the extension must be .stl, .ply or .obj",
                    path.display()
                ),
            }),
        }
    }
}

impl Mesh {
    /// Writes the mesh in the format `path`'s extension names.
    ///
    /// # Errors
    /// [`Error::Invalid`] for an unknown extension; as [`Mesh::write_as`].
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        self.write_as(path, MeshFormat::from_path(path)?)
    }

    /// Writes the mesh in `format`, atomically, as
    /// [`save_png`](crate::output::save_png) writes images.
    ///
    /// # Errors
    /// [`Error::Io`] naming `path` and what failed.
    pub fn write_as(&self, path: impl AsRef<Path>, format: MeshFormat) -> Result<()> {
        write_atomic(path.as_ref(), "mesh", |file| {
            let mut out = BufWriter::new(file);
            match format {
                MeshFormat::Stl => self.stl(&mut out)?,
                MeshFormat::Ply => self.ply(&mut out)?,
                MeshFormat::Obj => self.obj(&mut out)?,
            }
            out.flush()
        })
    }

    fn corners(&self, t: [u32; 3]) -> [Vec3; 3] {
        t.map(|i| self.positions[i as usize])
    }

    fn stl(&self, out: &mut BufWriter<&File>) -> io::Result<()> {
        let mut header = [b' '; 80];
        let title = b"binary STL written by fractal-sdf";
        header[..title.len()].copy_from_slice(title);
        out.write_all(&header)?;
        let count = u32::try_from(self.triangles.len())
            .map_err(|_| io::Error::other("STL holds at most 2^32 - 1 triangles"))?;
        out.write_all(&count.to_le_bytes())?;
        for t in &self.triangles {
            let [a, b, c] = self.corners(*t);
            let n = (b - a).cross(c - a).normalize_or_zero();
            for v in [n, a, b, c] {
                for x in v.to_array() {
                    out.write_all(&x.to_le_bytes())?;
                }
            }
            out.write_all(&[0, 0])?;
        }
        Ok(())
    }

    fn ply(&self, out: &mut BufWriter<&File>) -> io::Result<()> {
        write!(
            out,
            "ply\nformat binary_little_endian 1.0\ncomment written by fractal-sdf\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            self.positions.len(),
            self.triangles.len()
        )?;
        for (i, p) in self.positions.iter().enumerate() {
            let n = self.normals.get(i).copied().unwrap_or(Vec3::ZERO);
            for x in p.to_array().into_iter().chain(n.to_array()) {
                out.write_all(&x.to_le_bytes())?;
            }
            out.write_all(&self.colors.get(i).copied().unwrap_or([255; 3]))?;
        }
        for t in &self.triangles {
            out.write_all(&[3])?;
            for i in t {
                let i = i32::try_from(*i)
                    .map_err(|_| io::Error::other("PLY indices are 32-bit signed"))?;
                out.write_all(&i.to_le_bytes())?;
            }
        }
        Ok(())
    }

    fn obj(&self, out: &mut BufWriter<&File>) -> io::Result<()> {
        writeln!(out, "# written by fractal-sdf")?;
        for (i, p) in self.positions.iter().enumerate() {
            let [r, g, b] = self.colors.get(i).copied().unwrap_or([255; 3]);
            let c = |v: u8| f32::from(v) / 255.0;
            writeln!(out, "v {} {} {} {} {} {}", p.x, p.y, p.z, c(r), c(g), c(b))?;
        }
        if self.normals.len() == self.positions.len() {
            for n in &self.normals {
                writeln!(out, "vn {} {} {}", n.x, n.y, n.z)?;
            }
        }
        let with_normals = self.normals.len() == self.positions.len();
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| u64::from(i) + 1);
            if with_normals {
                writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
            } else {
                writeln!(out, "f {a} {b} {c}")?;
            }
        }
        Ok(())
    }
}
