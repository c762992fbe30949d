//! ΣΔ probe design: NTF synthesis, the modulator, probe waveforms and the ROM they fill.
