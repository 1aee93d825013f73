//! Reading a `.vgate` file: the header (magic, version, checksum), the section table, each
//! section checked and decoded, and the level validated whole.

use std::path::Path;

use super::{
    BakedLevel, Elem, FORMAT_VERSION, Header, MAGIC, OLDEST_READ_VERSION, PREFIX, SectionEntry,
    SectionKind, Topology, VoxelBits, VoxelValues, stated_version,
};
use crate::error::VgateError;

impl BakedLevel {
    /// Reads and fully validates a file.
    pub fn read(path: &Path) -> Result<BakedLevel, VgateError> {
        let bytes = std::fs::read(path).map_err(|error| VgateError::Io {
            file: path.to_path_buf(),
            error,
        })?;
        Self::from_bytes(&bytes)
    }

    /// Reads only the header (cheap: no section is decoded), after checking its checksum.
    pub fn read_header(bytes: &[u8]) -> Result<Header, VgateError> {
        let avail = bytes.len() as u64;
        if bytes.len() < PREFIX {
            if !MAGIC.starts_with(&bytes[..bytes.len().min(8)]) {
                return Err(VgateError::BadMagic);
            }
            return Err(VgateError::Truncated {
                what: "the fixed header",
                needed: PREFIX as u64,
                available: avail,
            });
        }
        let Some(version) = stated_version(bytes) else {
            return Err(VgateError::BadMagic);
        };
        if version > FORMAT_VERSION {
            return Err(VgateError::NewerVersion {
                found: version,
                supported: FORMAT_VERSION,
            });
        }
        if version < OLDEST_READ_VERSION {
            return Err(VgateError::OldVersion {
                found: version,
                supported: OLDEST_READ_VERSION,
            });
        }
        let hlen = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as u64;
        let hend = PREFIX as u64 + hlen;
        if hend + 4 > avail {
            return Err(VgateError::Truncated {
                what: "the header",
                needed: hend + 4,
                available: avail,
            });
        }
        let hend = hend as usize;
        let expected = u32::from_le_bytes([
            bytes[hend],
            bytes[hend + 1],
            bytes[hend + 2],
            bytes[hend + 3],
        ]);
        let found = crc32fast::hash(&bytes[..hend]);
        if found != expected {
            return Err(VgateError::Checksum {
                section: "header".into(),
                found,
                expected,
            });
        }
        let (header, rest): (Header, &[u8]) = postcard::take_from_bytes(&bytes[PREFIX..hend])
            .map_err(|e| VgateError::Decode {
                what: "header",
                message: e.to_string(),
            })?;
        if !rest.is_empty() {
            return Err(VgateError::Length(format!(
                "header declares {hlen} bytes but its contents end {} bytes earlier",
                rest.len()
            )));
        }
        Ok(header)
    }

    /// Decodes and fully validates a file's bytes.
    pub fn from_bytes(bytes: &[u8]) -> Result<BakedLevel, VgateError> {
        let header = Self::read_header(bytes)?;
        let slices = sections(bytes, &header)?;
        let topology = topology(slices[0])?;
        let voxels = header.info.grid.voxel_count().ok_or_else(|| {
            VgateError::BadValue(format!("grid dims {:?} overflow", header.info.grid.dims))
        })?;
        let sight = &header.info.sight_grid;
        let sight_voxels = sight.voxel_count().ok_or_else(|| {
            VgateError::BadValue(format!("sight grid dims {:?} overflow", sight.dims))
        })?;
        let level = BakedLevel {
            topology,
            voxel_cluster: voxel_cluster(slices[1], voxels)?,
            open: open_voxels(slices[2], sight_voxels)?,
            info: header.info,
        };
        level.validate()?;
        Ok(level)
    }
}

/// The three sections' entries and bytes, each where the one before ends, whole, with its
/// checksum right and a whole number of its elements, the last ending the file.
fn sections<'a>(
    bytes: &'a [u8],
    header: &'a Header,
) -> Result<Vec<(&'a SectionEntry, &'a [u8])>, VgateError> {
    let avail = bytes.len() as u64;
    let kinds: Vec<SectionKind> = header.sections.iter().map(|s| s.kind).collect();
    if !matches!(
        kinds[..],
        [
            SectionKind::Topology,
            SectionKind::VoxelCluster | SectionKind::VoxelClusterRuns,
            SectionKind::OpenVoxels | SectionKind::OpenVoxelRuns
        ]
    ) {
        return Err(VgateError::Length(format!(
            "section table lists {kinds:?}, expected the topology, the voxel clusters and the \
             open voxels"
        )));
    }
    let hlen = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]) as u64;
    let mut at = PREFIX as u64 + hlen + 4;
    let mut slices = Vec::with_capacity(3);
    for s in &header.sections {
        if s.offset != at {
            return Err(VgateError::Length(format!(
                "section {:?} starts at byte {}, expected {at}",
                s.kind, s.offset
            )));
        }
        let end = s
            .offset
            .checked_add(s.len)
            .ok_or_else(|| VgateError::Length(format!("section {:?} length overflows", s.kind)))?;
        if end > avail {
            return Err(VgateError::Truncated {
                what: "a section",
                needed: end,
                available: avail,
            });
        }
        let data = &bytes[s.offset as usize..end as usize];
        let found = crc32fast::hash(data);
        if found != s.crc32 {
            return Err(VgateError::Checksum {
                section: format!("{:?}", s.kind),
                found,
                expected: s.crc32,
            });
        }
        if s.kind != SectionKind::VoxelClusterRuns && s.len % s.elem.size() != 0 {
            return Err(VgateError::Length(format!(
                "section {:?} is {} bytes, not a whole number of {:?} elements",
                s.kind, s.len, s.elem
            )));
        }
        slices.push((s, data));
        at = end;
    }
    if at != avail {
        return Err(VgateError::Length(format!(
            "the file has {} bytes after its last section",
            avail - at
        )));
    }
    Ok(slices)
}

/// The topology section's structure, and nothing after it.
fn topology((s, data): (&SectionEntry, &[u8])) -> Result<Topology, VgateError> {
    if s.elem != Elem::Structure {
        return Err(VgateError::Length(
            "topology section is not a structure".into(),
        ));
    }
    let (t, rest) = postcard::take_from_bytes(data).map_err(|e| VgateError::Decode {
        what: "topology",
        message: e.to_string(),
    })?;
    if !rest.is_empty() {
        return Err(VgateError::Length(format!(
            "topology section has {} bytes after its structure",
            rest.len()
        )));
    }
    Ok(t)
}

/// The voxels' clusters, dense or as runs over the grid's `voxels`.
fn voxel_cluster(
    (s, data): (&SectionEntry, &[u8]),
    voxels: u64,
) -> Result<VoxelValues, VgateError> {
    if s.elem == Elem::Structure {
        return Err(VgateError::Length(format!(
            "section {:?} must be a blob of integers",
            s.kind
        )));
    }
    if s.kind == SectionKind::VoxelClusterRuns {
        VoxelValues::from_runs_le_bytes(s.elem, data, voxels)
            .map_err(|e| VgateError::Length(format!("voxel cluster runs: {e}")))
    } else {
        Ok(VoxelValues::from_le_bytes(s.elem, data))
    }
}

/// The sight grid's open voxels, as bits or as runs over its `voxels`.
fn open_voxels((s, data): (&SectionEntry, &[u8]), voxels: u64) -> Result<VoxelBits, VgateError> {
    if s.elem != Elem::U8 {
        return Err(VgateError::Length(
            "the open voxels' section is not a blob of bytes".into(),
        ));
    }
    if s.kind == SectionKind::OpenVoxelRuns {
        VoxelBits::from_runs_le_bytes(data, voxels)
    } else {
        VoxelBits::from_le_bytes(data, voxels)
    }
    .map_err(|e| VgateError::Length(format!("open voxels: {e}")))
}
