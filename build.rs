//! Gives every binary, test and bench of this package an rpath to the folder
//! holding libembree4, which the `raycheck-reference` build script found or
//! fetched (it exports that folder as `DEP_EMBREE4_ROOT` through `links`).
fn main() {
    println!("cargo:rerun-if-env-changed=DEP_EMBREE4_ROOT");
    if let Ok(dir) = std::env::var("DEP_EMBREE4_ROOT") {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
