//! The `unfold` binary: the command line of [`unfold::cli`] with the built-in schemes.

use std::process::ExitCode;

fn main() -> ExitCode {
    unfold::internal::install_hook();
    unfold::cli::main(&unfold::scheme::Registry::default(), std::env::args_os())
}
