//! The file formats scenes load from, one loader per file: scene
//! manifests (TOML), OBJ with its MTL, PLY (ASCII or binary, gzip or not),
//! glTF binary with Draco meshes, and an npm module holding a GLB as a
//! data URI; with the line-numbered text and gzip helpers they share.
//! Every loader names the file, and the line where the format has lines,
//! in each error.

pub mod data_uri_module;
pub mod glb;
mod gzip;
pub mod manifest;
pub mod obj;
pub mod ply;
mod text;
