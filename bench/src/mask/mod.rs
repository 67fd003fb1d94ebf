//! Paper 000 Table 1's masking experiment on a textured floor (`make
//! bench-mask`): a Cornell-like room whose floor carries a fine,
//! high-contrast checkerboard ([`scene`]), the full final gather with and
//! without the visual mask, and their work and error against a brute-force
//! reference per pixel, over the image and on the floor ([`table`]).

pub mod scene;
pub mod table;
