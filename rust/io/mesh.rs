//! Mesh files: Wavefront OBJ (text, with `vt` and `vn`) and PLY (binary
//! little-endian, with normals, texture coordinates `s t`, and per-face
//! `part_id`, `kind`, `color`, `instance`). Both are written to a temporary
//! file beside the target and renamed over it, so a file appears whole or
//! not at all.
use crate::error::{CoreError, CoreResult};
use crate::geometry::Mesh;
use crate::io::image_io::temp_path;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

fn io_err(path: &Path, e: std::io::Error) -> CoreError {
    CoreError::from_io(path.display(), &e)
}

fn atomic<F: FnOnce(&mut BufWriter<File>) -> std::io::Result<()>>(
    path: &Path,
    f: F,
) -> CoreResult<()> {
    if let Some(dir) = path.parent() {
        if !dir.as_os_str().is_empty() && !dir.is_dir() {
            return Err(CoreError::NotFound(format!(
                "{}: folder does not exist",
                path.display()
            )));
        }
    }
    let tmp = temp_path(path);
    let res = (|| {
        let file = File::create(&tmp)?;
        let mut w = BufWriter::with_capacity(1 << 20, file);
        f(&mut w)?;
        w.flush()?;
        w.get_ref().sync_all()?;
        Ok(())
    })();
    if let Err(e) = res {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_err(path, e));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io_err(path, e)
    })
}

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ, text ([`write_obj`]).
    Obj,
    /// Binary little-endian PLY ([`write_ply`]).
    Ply,
}

impl MeshFormat {
    /// Parse `"obj"` or `"ply"` (errors name `format`).
    pub fn parse(s: &str) -> CoreResult<Self> {
        match s {
            "obj" => Ok(MeshFormat::Obj),
            "ply" => Ok(MeshFormat::Ply),
            _ => Err(CoreError::invalid(
                "format",
                format!("expected 'obj' or 'ply', got {s:?}"),
            )),
        }
    }
}

/// Write `mesh` to `path` as `format`, atomically.
pub fn write_mesh(mesh: &Mesh, path: &Path, format: MeshFormat) -> CoreResult<()> {
    write_mesh_with(mesh, path, format, &[], &[])
}

/// Write `mesh` to `path` as `format`, atomically, with extra header lines
/// `comments` (OBJ `#` comments, PLY `comment` lines; line breaks become
/// spaces) and the OBJ group name of each kind (`groups[k]` for kind `k`;
/// see [`write_obj_with`]).
pub fn write_mesh_with(
    mesh: &Mesh,
    path: &Path,
    format: MeshFormat,
    comments: &[String],
    groups: &[String],
) -> CoreResult<()> {
    match format {
        MeshFormat::Obj => write_obj_with(mesh, path, comments, groups),
        MeshFormat::Ply => write_ply_with(mesh, path, comments),
    }
}

/// One header line: line breaks become spaces.
fn one_line(s: &str) -> String {
    s.replace(['\n', '\r'], " ")
}

/// The OBJ group name of triangles of `kind`: `groups[kind]` (whitespace
/// as `_`), else `branches` (0), `leaves` (1), `kind<k>`.
fn group_name(kind: u8, groups: &[String]) -> String {
    match groups.get(kind as usize) {
        Some(g) if !g.trim().is_empty() => g.split_whitespace().collect::<Vec<_>>().join("_"),
        _ => match kind {
            0 => "branches".to_string(),
            1 => "leaves".to_string(),
            k => format!("kind{k}"),
        },
    }
}

/// Write `mesh` as Wavefront OBJ (1-based `f v/vt/vn` faces; branches and
/// leaves in groups `branches` and `leaves`).
pub fn write_obj(mesh: &Mesh, path: &Path) -> CoreResult<()> {
    write_obj_with(mesh, path, &[], &[])
}

/// Write `mesh` as Wavefront OBJ with extra `#` header lines `comments`:
/// 1-based `f v/vt/vn` faces, every triangle in the group of its kind, the
/// kinds in increasing order (names from [`group_name`]).
pub fn write_obj_with(
    mesh: &Mesh,
    path: &Path,
    comments: &[String],
    groups: &[String],
) -> CoreResult<()> {
    mesh.check_layout()?;
    let mut present = [false; 256];
    for &k in &mesh.kinds {
        present[k as usize] = true;
    }
    atomic(path, |w| {
        writeln!(
            w,
            "# fractalgeo_rs mesh: {} vertices, {} triangles",
            mesh.vertices.len(),
            mesh.faces.len()
        )?;
        for c in comments {
            writeln!(w, "# {}", one_line(c))?;
        }
        for v in &mesh.vertices {
            writeln!(w, "v {} {} {}", v[0], v[1], v[2])?;
        }
        for t in &mesh.uvs {
            writeln!(w, "vt {} {}", t[0], t[1])?;
        }
        for n in &mesh.normals {
            writeln!(w, "vn {} {} {}", n[0], n[1], n[2])?;
        }
        for kind in (0..=255u8).filter(|&k| present[k as usize]) {
            writeln!(w, "g {}", group_name(kind, groups))?;
            for (f, _) in mesh
                .faces
                .iter()
                .zip(&mesh.kinds)
                .filter(|(_, &k)| k == kind)
            {
                let (a, b, c) = (f[0] + 1, f[1] + 1, f[2] + 1);
                writeln!(w, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}")?;
            }
        }
        Ok(())
    })
}

/// Write `mesh` as binary little-endian PLY.
pub fn write_ply(mesh: &Mesh, path: &Path) -> CoreResult<()> {
    write_ply_with(mesh, path, &[])
}

/// Write `mesh` as binary little-endian PLY with extra `comment` header
/// lines `comments`.
pub fn write_ply_with(mesh: &Mesh, path: &Path, comments: &[String]) -> CoreResult<()> {
    mesh.check_layout()?;
    atomic(path, |w| {
        write!(
            w,
            "ply\nformat binary_little_endian 1.0\ncomment fractalgeo_rs mesh\n"
        )?;
        for c in comments {
            writeln!(w, "comment {}", one_line(c))?;
        }
        write!(
            w,
            "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n\
             element face {}\nproperty list uchar uint vertex_indices\nproperty uint part_id\n\
             property uchar kind\nproperty uint color\nproperty uint instance\nend_header\n",
            mesh.vertices.len(),
            mesh.faces.len()
        )?;
        let mut buf = Vec::with_capacity(32);
        for i in 0..mesh.vertices.len() {
            buf.clear();
            for x in mesh.vertices[i]
                .iter()
                .chain(&mesh.normals[i])
                .chain(&mesh.uvs[i])
            {
                buf.extend_from_slice(&x.to_le_bytes());
            }
            w.write_all(&buf)?;
        }
        for i in 0..mesh.faces.len() {
            buf.clear();
            buf.push(3u8);
            for x in mesh.faces[i] {
                buf.extend_from_slice(&x.to_le_bytes());
            }
            buf.extend_from_slice(&mesh.part_ids[i].to_le_bytes());
            buf.push(mesh.kinds[i]);
            buf.extend_from_slice(&mesh.colors[i].to_le_bytes());
            buf.extend_from_slice(&mesh.instances[i].to_le_bytes());
            w.write_all(&buf)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lsystem::grammar::parse_module_string;
    use crate::lsystem::mesh::build_mesh;
    use crate::lsystem::turtle::TurtleParams;

    #[test]
    fn mesh_format_parses_and_names_the_parameter() {
        assert_eq!(MeshFormat::parse("obj").unwrap(), MeshFormat::Obj);
        assert_eq!(MeshFormat::parse("ply").unwrap(), MeshFormat::Ply);
        match MeshFormat::parse("stl") {
            Err(CoreError::InvalidArgument { param, .. }) => assert_eq!(param, "format"),
            other => panic!("expected InvalidArgument, got {other:?}"),
        }
    }

    #[test]
    fn obj_and_ply_round_trip_counts() {
        let s = parse_module_string("F[+F]{.f.+f.+f.}", "axiom").unwrap();
        let m = build_mesh(&s, &TurtleParams::spatial(60.0, 1.0), 5).unwrap();
        let dir = std::env::temp_dir().join(format!("fgrs-lsys-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let obj = dir.join("a.obj");
        write_obj(&m, &obj).unwrap();
        let text = std::fs::read_to_string(&obj).unwrap();
        let count = |p: &str| text.lines().filter(|l| l.starts_with(p)).count();
        assert_eq!(count("v "), m.vertices.len());
        assert_eq!(count("vt "), m.vertices.len());
        assert_eq!(count("vn "), m.vertices.len());
        assert_eq!(count("f "), m.faces.len());
        let ply = dir.join("a.ply");
        write_ply(&m, &ply).unwrap();
        let bytes = std::fs::read(&ply).unwrap();
        let head = b"end_header\n";
        let pos = bytes.windows(head.len()).position(|w| w == head).unwrap() + head.len();
        assert_eq!(
            bytes.len() - pos,
            m.vertices.len() * 32 + m.faces.len() * (1 + 12 + 4 + 1 + 4 + 4)
        );
        // no temporary file is left behind
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
        assert!(write_obj(&m, &dir.join("missing/a.obj")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn every_kind_is_written_with_its_group_and_the_comments() {
        let s = parse_module_string("F[+F]{.f.+f.+f.}", "axiom").unwrap();
        let mut m = build_mesh(&s, &TurtleParams::spatial(60.0, 1.0), 5).unwrap();
        // kinds 0, 1, 2 and 7 as a plant stand's soil, bark, leaves and more
        for (i, k) in m.kinds.iter_mut().enumerate() {
            *k = [0u8, 1, 2, 7][i % 4];
        }
        let dir = std::env::temp_dir().join(format!("fgrs-kinds-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let obj = dir.join("k.obj");
        let comments = ["offset 1.5 2 0".to_string(), "two\nlines".to_string()];
        let groups = [
            "soil".to_string(),
            "bark".to_string(),
            "leaf blades".to_string(),
        ];
        write_obj_with(&m, &obj, &comments, &groups).unwrap();
        let text = std::fs::read_to_string(&obj).unwrap();
        assert_eq!(
            text.lines().filter(|l| l.starts_with("f ")).count(),
            m.faces.len()
        );
        let g: Vec<&str> = text.lines().filter(|l| l.starts_with("g ")).collect();
        assert_eq!(g, ["g soil", "g bark", "g leaf_blades", "g kind7"]);
        assert!(text.lines().any(|l| l == "# offset 1.5 2 0"));
        assert!(text.lines().any(|l| l == "# two lines"));
        let ply = dir.join("k.ply");
        write_ply_with(&m, &ply, &comments).unwrap();
        let bytes = std::fs::read(&ply).unwrap();
        let head = b"end_header\n";
        let pos = bytes.windows(head.len()).position(|w| w == head).unwrap() + head.len();
        let header = String::from_utf8(bytes[..pos].to_vec()).unwrap();
        assert!(header.lines().any(|l| l == "comment offset 1.5 2 0"));
        assert_eq!(
            bytes.len() - pos,
            m.vertices.len() * 32 + m.faces.len() * (1 + 12 + 4 + 1 + 4 + 4)
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
