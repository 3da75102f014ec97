//! Recorded body poses per step, their hash, and the NPZ output.

use std::path::Path;

use anyhow::{Context, Result};
use ndarray::{Array1, Array3};
use ndarray_npy::NpzWriter;
use sha2::{Digest, Sha256};

/// Poses of the recorded (dynamic) bodies at every step, including the initial state.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    /// Body names, in column order.
    pub names: Vec<String>,
    /// Time of each row (s).
    pub time: Vec<f64>,
    /// Positions (m, world), row-major `[row][body][xyz]`.
    pub positions: Vec<f64>,
    /// Rotations as unit quaternions `[x, y, z, w]`, `[row][body][xyzw]`.
    pub rotations: Vec<f64>,
}

impl Trajectory {
    /// Number of rows (steps + 1).
    pub fn rows(&self) -> usize {
        self.time.len()
    }

    /// Position of body `b` at row `k`.
    pub fn pos(&self, k: usize, b: usize) -> [f64; 3] {
        let i = (k * self.names.len() + b) * 3;
        [
            self.positions[i],
            self.positions[i + 1],
            self.positions[i + 2],
        ]
    }

    /// Rotation (x, y, z, w) of body `b` at row `k`.
    pub fn rot(&self, k: usize, b: usize) -> [f64; 4] {
        let i = (k * self.names.len() + b) * 4;
        [
            self.rotations[i],
            self.rotations[i + 1],
            self.rotations[i + 2],
            self.rotations[i + 3],
        ]
    }

    /// `sha256:` of every recorded position and rotation bit pattern (determinism check).
    pub fn hash(&self) -> String {
        let mut h = Sha256::new();
        for x in self.positions.iter().chain(self.rotations.iter()) {
            h.update(x.to_bits().to_le_bytes());
        }
        format!("sha256:{:x}", h.finalize())
    }

    /// Writes `time` (n), `positions` (n × bodies × 3) and `rotations` (n × bodies × 4,
    /// xyzw) to an NPZ file (through the one writer, [`dcr_files::write_atomic`]).
    ///
    /// # Errors
    /// I/O errors, or a destination the writer refuses (a device, FIFO or folder).
    pub fn write_npz(&self, path: &Path) -> Result<()> {
        let bytes = self.to_npz()?;
        dcr_files::write_atomic(path, &bytes).with_context(|| format!("writing {}", path.display()))
    }

    /// The NPZ file [`Trajectory::write_npz`] writes, in memory.
    ///
    /// # Errors
    /// When the arrays do not match the names (a recorder bug).
    pub fn to_npz(&self) -> Result<Vec<u8>> {
        let n = self.rows();
        let b = self.names.len();
        let mut npz = NpzWriter::new(std::io::Cursor::new(Vec::new()));
        npz.add_array("time", &Array1::from(self.time.clone()))?;
        npz.add_array(
            "positions",
            &Array3::from_shape_vec((n, b, 3), self.positions.clone())?,
        )?;
        npz.add_array(
            "rotations",
            &Array3::from_shape_vec((n, b, 4), self.rotations.clone())?,
        )?;
        Ok(npz.finish()?.into_inner())
    }
}
