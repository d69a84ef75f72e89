fn main() {
    std::process::exit(mcgv_video::cli::main());
}
