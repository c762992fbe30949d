//! Scene motion δ(t) and the photon/TDC Monte Carlo.
