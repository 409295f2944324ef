//! The `shpb` binary: a thin wrapper over [`shpb::cli`].

fn main() {
    std::process::exit(shpb::cli::main());
}
