//! Start-up: built by `make` (HDF5_DIR on the Makefile's `hdf5-static` shim), the binary links
//! Debian's static HDF5 archive, so a process loads no libhdf5 and none of the network libraries
//! (libcurl, GnuTLS, Kerberos, LDAP) Debian's shared libhdf5 pulls in
//! (validation/perf/REPORT.md, "Start-up"). A plain `cargo test` links the shared library by
//! design; the test then has nothing to check and says so.

use std::path::Path;
use std::process::Command;

#[test]
fn make_links_hdf5_statically() {
    let shim = match std::env::var_os("HDF5_DIR") {
        Some(dir) if Path::new(&dir).join("lib/libhdf5.so").is_file() => dir,
        _ => {
            eprintln!("HDF5_DIR is not the static shim (not built by make): nothing to check");
            return;
        }
    };
    let out = Command::new("ldd")
        .arg(env!("CARGO_BIN_EXE_shpb"))
        .output()
        .expect("ldd runs");
    assert!(out.status.success(), "ldd failed");
    let libs = String::from_utf8_lossy(&out.stdout);
    for unwanted in ["libhdf5", "libcurl", "libgnutls", "libkrb5", "libldap"] {
        assert!(
            !libs.contains(unwanted),
            "built with HDF5_DIR = {shim:?}, the binary still loads {unwanted}:\n{libs}"
        );
    }
    // The binary still writes HDF5 (from the archive).
    let dir = tempfile::tempdir().unwrap();
    let h5 = dir.path().join("out.h5");
    let run = Command::new(env!("CARGO_BIN_EXE_shpb"))
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .args(["run", "scenes/collision-ss440c-5ms.toml", "-q", "-o"])
        .arg(&h5)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let dump = Command::new("h5dump")
        .args(["-H"])
        .arg(&h5)
        .output()
        .unwrap();
    assert!(
        dump.status.success(),
        "h5dump cannot read the file the static binary wrote"
    );
}
