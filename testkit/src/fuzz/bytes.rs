//! A dependency-free reader of fuzz input bytes. Reads past the end return zeros, so every byte
//! string is a valid input.

pub struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Bytes<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Self { data, pos: 0 }
    }

    #[allow(dead_code)] // not every harness uses it
    pub fn is_empty(&self) -> bool {
        self.pos >= self.data.len()
    }

    pub fn u8(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos = self.pos.saturating_add(1);
        b
    }

    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }

    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }

    /// The rest of the input (possibly empty).
    #[allow(dead_code)] // not every harness uses it
    pub fn rest(&mut self) -> &'a [u8] {
        let start = self.pos.min(self.data.len());
        self.pos = self.data.len();
        &self.data[start..]
    }

    /// A float that is often special: NaN, infinities, zeros, subnormal, huge, or `typical`
    /// scaled by a factor in [0.25, 4); else raw bits.
    pub fn f32_near(&mut self, typical: f32) -> f32 {
        match self.u8() % 16 {
            0 => f32::NAN,
            1 => f32::INFINITY,
            2 => f32::NEG_INFINITY,
            3 => 0.0,
            4 => -0.0,
            5 => f32::MIN_POSITIVE / 4.0,
            6 => f32::MAX,
            7 => 1e30,
            8 => -typical,
            9 => f32::from_bits(self.u32()),
            _ => typical * (0.25 + self.u8() as f32 / 64.0),
        }
    }
}
