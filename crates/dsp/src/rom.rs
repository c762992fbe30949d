//! The probe ROM image the chip stores: 2·B bits per pulse index (register r = 2k is I of
//! bin k, 2k+1 is Q of bin k), addressed by pulse index mod depth L. Bit 1 means the pixel
//! adds its operand to that register, 0 that it subtracts.
//!
//! Bits are packed little-endian into u64 words, `words_per_entry` words per address, so the
//! pixel model reads one entry per pulse without unpacking.

/// A bit-packed probe ROM: `depth` entries of `registers` bits.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RomImage {
    depth: usize,
    registers: usize,
    words_per_entry: usize,
    data: Vec<u64>,
}

impl RomImage {
    /// A ROM of all-zero bits (every register subtracts).
    pub fn zeros(depth: usize, registers: usize) -> Self {
        let words_per_entry = registers.div_ceil(64).max(1);
        RomImage {
            depth,
            registers,
            words_per_entry,
            data: vec![0; depth * words_per_entry],
        }
    }

    /// Builds a ROM from a bit function `bit(address, register)`.
    pub fn from_fn(
        depth: usize,
        registers: usize,
        mut bit: impl FnMut(usize, usize) -> bool,
    ) -> Self {
        let mut rom = RomImage::zeros(depth, registers);
        for a in 0..depth {
            for r in 0..registers {
                if bit(a, r) {
                    rom.set_bit(a, r, true);
                }
            }
        }
        rom
    }

    /// Number of addresses L.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// Bits per address (2·B).
    pub fn registers(&self) -> usize {
        self.registers
    }

    /// u64 words per address.
    pub fn words_per_entry(&self) -> usize {
        self.words_per_entry
    }

    /// The packed entry at `address` (bit r of the entry is bit r % 64 of word r / 64).
    #[inline]
    pub fn entry(&self, address: usize) -> &[u64] {
        let s = address * self.words_per_entry;
        &self.data[s..s + self.words_per_entry]
    }

    /// One bit.
    #[inline]
    pub fn bit(&self, address: usize, register: usize) -> bool {
        (self.entry(address)[register / 64] >> (register % 64)) & 1 == 1
    }

    /// Sets one bit.
    pub fn set_bit(&mut self, address: usize, register: usize, value: bool) {
        let w = &mut self.data[address * self.words_per_entry + register / 64];
        let m = 1u64 << (register % 64);
        if value {
            *w |= m;
        } else {
            *w &= !m;
        }
    }

    /// All packed words, entry after entry.
    pub fn words(&self) -> &[u64] {
        &self.data
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_round_trip_across_word_boundaries() {
        // 70 registers span two words per entry; a pattern that differs per address and
        // register catches any packing offset error.
        let f = |a: usize, r: usize| (a * 7 + r * 3) % 5 < 2;
        let rom = RomImage::from_fn(9, 70, f);
        assert_eq!(rom.words_per_entry(), 2);
        for a in 0..9 {
            for r in 0..70 {
                assert_eq!(rom.bit(a, r), f(a, r), "address {a} register {r}");
            }
        }
    }
}
