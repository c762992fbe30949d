//! Float references that every cheaper or bit-true path is judged against: windows, full
//! and selected-bin DFTs, the pixel's pre-processing in float, spectrum statistics, Haar
//! wavelets, closed-form noise/bandwidth/pile-up models, and the ΣΔ probe design that
//! produces the chip's bitstream ROM.

pub mod closed_form;
pub mod dft;
pub mod error;
pub mod haar;
pub mod imputation;
pub mod preprocess;
pub mod rom;
pub mod scene_analysis;
pub mod sd;
pub mod selected_bins;
pub mod stats;
pub mod superpixel;
pub mod window;

pub use error::DspError;
pub use rom::RomImage;
pub use window::Window;
