//! Byte-level helpers shared by the request and reply codecs: a bounds-checked reader over a
//! frame's data and a bounded writer that builds one.

use heapless::Vec;

use crate::frame::{Frame, MAX_DATA};
use crate::units::{Centideg, DeciMm, Steps};

use super::types::Pose;

/// Reads big-endian fields from a frame's data; every read past the end is `None`.
pub(crate) struct Reader<'a> {
    data: &'a [u8],
}

impl<'a> Reader<'a> {
    pub(crate) fn new(data: &'a [u8]) -> Self {
        Self { data }
    }

    /// Bytes not read yet.
    pub(crate) fn remaining(&self) -> usize {
        self.data.len()
    }

    /// Every byte not read yet.
    pub(crate) fn rest(&mut self) -> &'a [u8] {
        core::mem::take(&mut self.data)
    }

    pub(crate) fn u8(&mut self) -> Option<u8> {
        let (&first, rest) = self.data.split_first()?;
        self.data = rest;
        Some(first)
    }

    pub(crate) fn i16(&mut self) -> Option<i16> {
        let hi = self.u8()?;
        let lo = self.u8()?;
        Some(i16::from_be_bytes([hi, lo]))
    }

    pub(crate) fn i16x6(&mut self) -> Option<[i16; 6]> {
        let mut out = [0i16; 6];
        for v in &mut out {
            *v = self.i16()?;
        }
        Some(out)
    }

    pub(crate) fn centideg6(&mut self) -> Option<[Centideg; 6]> {
        self.i16x6().map(|a| a.map(Centideg))
    }

    pub(crate) fn steps6(&mut self) -> Option<[Steps; 6]> {
        self.i16x6().map(|a| a.map(Steps))
    }

    pub(crate) fn pose(&mut self) -> Option<Pose> {
        let [x, y, z, rx, ry, rz] = self.i16x6()?;
        Some(Pose {
            x: DeciMm(x),
            y: DeciMm(y),
            z: DeciMm(z),
            rx: Centideg(rx),
            ry: Centideg(ry),
            rz: Centideg(rz),
        })
    }

    pub(crate) fn u8x<const N: usize>(&mut self) -> Option<[u8; N]> {
        let mut out = [0u8; N];
        for v in &mut out {
            *v = self.u8()?;
        }
        Some(out)
    }
}

/// Builds a frame's data; bytes beyond [`MAX_DATA`] are dropped (no layout is longer: only the
/// free-form payload of 0xB0 reaches it).
#[derive(Default)]
pub(crate) struct Writer {
    data: Vec<u8, MAX_DATA>,
}

impl Writer {
    pub(crate) fn u8(&mut self, v: u8) -> &mut Self {
        let _ = self.data.push(v);
        self
    }

    pub(crate) fn bytes(&mut self, v: &[u8]) -> &mut Self {
        for &b in v {
            self.u8(b);
        }
        self
    }

    pub(crate) fn i16(&mut self, v: i16) -> &mut Self {
        self.bytes(&v.to_be_bytes())
    }

    pub(crate) fn i16s(&mut self, v: &[i16]) -> &mut Self {
        for &x in v {
            self.i16(x);
        }
        self
    }

    pub(crate) fn centideg6(&mut self, v: &[Centideg; 6]) -> &mut Self {
        self.i16s(&v.map(|a| a.0))
    }

    pub(crate) fn steps6(&mut self, v: &[Steps; 6]) -> &mut Self {
        self.i16s(&v.map(|a| a.0))
    }

    pub(crate) fn pose(&mut self, p: &Pose) -> &mut Self {
        self.i16s(&p.to_array())
    }

    pub(crate) fn frame(&self, cmd: u8) -> Frame {
        // The data never exceeds MAX_DATA (the Vec's capacity), so Frame::new cannot fail.
        Frame::new(cmd, &self.data).unwrap_or_default()
    }
}
