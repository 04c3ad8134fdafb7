//! The training data: labelled samples and surface points in the unit cube.

use crate::error::TrainError;

/// Training samples in the unit-cube frame with their ground-truth occupancy.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrainingData {
    /// #N×3 points.
    pub points: Vec<[f64; 3]>,
    /// #N occupancy (true = inside).
    pub occupancy: Vec<bool>,
    /// Points on the surface (area-uniform) for [`Init::Surface`]; may be empty otherwise.
    pub surface: Vec<[f64; 3]>,
    /// Unit normals at `surface` (any orientation: labels come from the solid).
    pub normals: Vec<[f64; 3]>,
}

impl TrainingData {
    /// A fingerprint of the data (FNV-1a over the bits), stored in checkpoints so a resume
    /// on different data is refused.
    pub fn fingerprint(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |x: u64| {
            for b in x.to_le_bytes() {
                h ^= b as u64;
                h = h.wrapping_mul(0x0100_0000_01b3);
            }
        };
        eat(self.points.len() as u64);
        for (p, &o) in self.points.iter().zip(&self.occupancy) {
            eat(p[0].to_bits());
            eat(p[1].to_bits());
            eat(p[2].to_bits());
            eat(o as u64);
        }
        h
    }

    pub(crate) fn validate(&self) -> Result<(), TrainError> {
        if self.points.is_empty() || self.points.len() != self.occupancy.len() {
            return Err(TrainError::Data(format!(
                "{} points with {} occupancy values; need at least one of each, the same number",
                self.points.len(),
                self.occupancy.len()
            )));
        }
        if let Some(i) = self.points.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
            return Err(TrainError::Data(format!("point {i} is not finite: {:?}", self.points[i])));
        }
        Ok(())
    }
}
