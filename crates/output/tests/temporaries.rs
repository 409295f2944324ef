//! A process stopped by a signal removes the temporary files of its writes in progress
//! (`atomic::remove_temporaries`, what `shpb` calls on SIGINT/SIGTERM). Its own test binary:
//! the registry of temporary files is global to the process.

use shpb_output::atomic::{remove_temporaries, write_atomically};

#[test]
fn a_stopped_process_removes_the_temporary_files_of_writes_in_progress() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.csv");
    let (started_tx, started_rx) = std::sync::mpsc::channel();
    let (go_tx, go_rx) = std::sync::mpsc::channel::<()>();
    let writer = {
        let out = out.clone();
        std::thread::spawn(move || {
            write_atomically(&out, false, |tmp| {
                std::fs::write(tmp, "partial").unwrap();
                started_tx.send(tmp.to_path_buf()).unwrap();
                let _ = go_rx.recv();
                Ok(())
            })
        })
    };
    let tmp = started_rx.recv().unwrap();
    assert!(tmp.exists());
    let held = remove_temporaries();
    assert!(!tmp.exists(), "the temporary file is removed");
    // The names stay listed, for the second removal just before the process exits.
    assert_eq!(held.as_slice(), std::slice::from_ref(&tmp));
    go_tx.send(()).unwrap();
    // While the guard is held the write cannot be renamed into place.
    std::thread::sleep(std::time::Duration::from_millis(50));
    assert!(!out.exists());
    drop(held);
    // (A stopped process would have exited; here the rename finds no temporary file.)
    assert!(writer.join().unwrap().is_err());
    assert!(!out.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // A write that is not interrupted leaves its output and nothing else.
    write_atomically(&out, false, |tmp| {
        std::fs::write(tmp, "whole").map_err(|e| shpb_input::Error::io(tmp, e))
    })
    .unwrap();
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "whole");
    assert!(remove_temporaries().is_empty());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}
