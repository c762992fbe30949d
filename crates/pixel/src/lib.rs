//! Bit-true pixel model. See docs/pixel-contract.md.
