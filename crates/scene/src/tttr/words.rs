//! The 32-bit record words of a time-tagged file, read in fixed blocks so that a file of
//! 10^9 records streams in bounded memory (one block, 256 KiB).

use std::io::Read;

use crate::error::SceneError;

/// Bytes per read block (a multiple of 4).
const BLOCK_BYTES: usize = 1 << 18;

/// Little-endian u32 words after a header, with the position of each for error messages.
#[derive(Debug)]
pub(crate) struct WordReader<R> {
    inner: R,
    file: String,
    /// Byte offset of the first record word in the file (the header's length).
    data_offset: u64,
    /// Records the header promises (PTU `TTResult_NumberOfRecords`), if it says.
    expected: Option<u64>,
    buf: Vec<u8>,
    pos: usize,
    len: usize,
    /// Index of the next word to hand out.
    index: u64,
    eof: bool,
}

impl<R: Read> WordReader<R> {
    pub(crate) fn new(inner: R, file: &str, data_offset: u64, expected: Option<u64>) -> Self {
        WordReader {
            inner,
            file: file.to_string(),
            data_offset,
            expected,
            buf: vec![0; BLOCK_BYTES],
            pos: 0,
            len: 0,
            index: 0,
            eof: false,
        }
    }

    /// Index of the next record (the number handed out so far).
    pub(crate) fn index(&self) -> u64 {
        self.index
    }

    /// `record 12 (byte 5848)`: where record `index` lies in the file.
    pub(crate) fn at(&self, index: u64) -> String {
        format!("record {index} (byte {})", self.data_offset + 4 * index)
    }

    /// The next word, `None` at the end of the records, or an error for a truncated file.
    #[inline]
    pub(crate) fn next_word(&mut self) -> Result<Option<u32>, SceneError> {
        if self.expected.is_some_and(|n| self.index >= n) {
            return Ok(None);
        }
        if self.len - self.pos < 4 {
            self.refill()?;
            if self.len - self.pos < 4 {
                return self.end();
            }
        }
        let b = &self.buf[self.pos..self.pos + 4];
        let w = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        self.pos += 4;
        self.index += 1;
        Ok(Some(w))
    }

    /// Moves the partial word left in the block to its front and reads until the block is
    /// full or the file ends.
    fn refill(&mut self) -> Result<(), SceneError> {
        if self.eof {
            return Ok(());
        }
        self.buf.copy_within(self.pos..self.len, 0);
        self.len -= self.pos;
        self.pos = 0;
        while self.len < self.buf.len() {
            match self.inner.read(&mut self.buf[self.len..]) {
                Ok(0) => {
                    self.eof = true;
                    break;
                }
                Ok(n) => self.len += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(SceneError::Tttr {
                        file: self.file.clone(),
                        at: self.at(self.index),
                        expected: "a readable file".into(),
                        found: format!("a read error: {e}"),
                    });
                }
            }
        }
        Ok(())
    }

    /// End of the data: fine if no record was promised or all were read, else truncated.
    fn end(&self) -> Result<Option<u32>, SceneError> {
        let partial = self.len - self.pos;
        match self.expected {
            Some(n) => Err(SceneError::Tttr {
                file: self.file.clone(),
                at: self.at(self.index),
                expected: format!("{n} records of 4 bytes (the header's TTResult_NumberOfRecords)"),
                found: format!(
                    "the end of the file after {} records{} (a truncated file)",
                    self.index,
                    if partial > 0 {
                        format!(" and {partial} stray bytes")
                    } else {
                        String::new()
                    }
                ),
            }),
            None if partial > 0 => Err(SceneError::Tttr {
                file: self.file.clone(),
                at: self.at(self.index),
                expected: "whole 4-byte records".into(),
                found: format!("{partial} stray bytes at the end of the file (a truncated file)"),
            }),
            None => Ok(None),
        }
    }
}
