//! SIGINT and SIGTERM: a stopped `shpb` removes the temporary files of the writes it has in
//! progress ([`shpb_output::atomic::remove_temporaries`]), says what it stopped (a sweep says how
//! to resume it, [`set_message`]) and exits with 128 + the signal number (130 for Ctrl-C, 143 for
//! SIGTERM).
//!
//! [`install`] blocks the two signals in the calling thread, so it must run first in `main`,
//! before any other thread starts (threads inherit the mask); one thread then waits for them
//! with `sigwait`, so nothing runs inside a signal handler.

use std::sync::Mutex;

/// What to say when stopped, as `shpb: stopped by SIGINT; <message>`.
type Message = Box<dyn Fn() -> String + Send>;

static MESSAGE: Mutex<Option<Message>> = Mutex::new(None);

/// Sets what a stop says after `shpb: stopped by SIG…` (replacing the previous message).
pub fn set_message(message: impl Fn() -> String + Send + 'static) {
    *MESSAGE.lock().unwrap_or_else(|e| e.into_inner()) = Some(Box::new(message));
}

/// Forgets the message (the work it described is done).
pub fn clear_message() {
    *MESSAGE.lock().unwrap_or_else(|e| e.into_inner()) = None;
}

/// Blocks SIGINT and SIGTERM in this thread (and the threads it starts) and starts the thread
/// that handles them. Call once, first thing in `main`.
pub fn install() {
    // SAFETY: plain libc calls on a local, zero-initialised signal set.
    let set = unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        libc::sigaddset(&mut set, libc::SIGINT);
        libc::sigaddset(&mut set, libc::SIGTERM);
        if libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) != 0 {
            return;
        }
        set
    };
    let spawned = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            loop {
                let mut signal: libc::c_int = 0;
                // SAFETY: `set` is a valid signal set, `signal` a valid out-pointer.
                if unsafe { libc::sigwait(&set, &mut signal) } == 0 {
                    stop(signal);
                }
            }
        });
    if spawned.is_err() {
        // Without the thread, restore the default action rather than ignore the signals.
        // SAFETY: as above.
        unsafe {
            libc::pthread_sigmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut());
        }
    }
}

/// Removes the temporary files, says what stopped and exits with 128 + `signal`.
fn stop(signal: libc::c_int) -> ! {
    // Held until exit: no write is renamed into place after its temporary file is gone.
    let writes = shpb_output::atomic::remove_temporaries();
    let name = if signal == libc::SIGTERM {
        "SIGTERM"
    } else {
        "SIGINT"
    };
    let message = MESSAGE
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .as_ref()
        .map(|m| m());
    // A progress bar may be on the current line of a terminal.
    let start = if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        "\n"
    } else {
        ""
    };
    match message {
        Some(m) => eprintln!("{start}shpb: stopped by {name}; {m}"),
        None => eprintln!("{start}shpb: stopped by {name}"),
    }
    // A writer on another thread may have created its temporary file again since the first
    // removal (it had the name before the lock was taken): removed once more, last thing.
    for tmp in writes.iter() {
        let _ = std::fs::remove_file(tmp);
    }
    // `_exit`, not `exit`: the exit handlers (the HDF5 library's among them) must not run while
    // another thread may be inside the library. Lines on stdout are flushed as they are printed.
    // SAFETY: `_exit` ends the process at once; nothing of ours needs running after this point.
    unsafe { libc::_exit(128 + signal) }
}

/// The command line of this process with `--force` removed and `--resume` added (if missing),
/// quoted for a POSIX shell: what resumes a stopped sweep.
pub fn resume_command() -> String {
    let args: Vec<String> = std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    let mut out: Vec<String> = Vec::new();
    for (i, a) in args.iter().enumerate() {
        if i > 0 && a == "--force" {
            continue;
        }
        out.push(shell_quote(a));
    }
    if !args.iter().skip(1).any(|a| a == "--resume") {
        out.push("--resume".into());
    }
    out.join(" ")
}

/// `text` quoted for a POSIX shell when it needs to be.
pub fn shell_quote(text: &str) -> String {
    let plain = !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+%@^".contains(c));
    if plain {
        text.to_string()
    } else {
        format!("'{}'", text.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_are_quoted_for_the_shell_when_needed() {
        assert_eq!(
            shell_quote("pressure=7psi:22psi:50"),
            "pressure=7psi:22psi:50"
        );
        assert_eq!(shell_quote("my study.h5"), "'my study.h5'");
        assert_eq!(shell_quote("it's"), r"'it'\''s'");
        assert_eq!(shell_quote(""), "''");
    }
}
