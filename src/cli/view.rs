//! `inksim view`: load the results, bind the server, print the address,
//! serve until Ctrl-C.

use anyhow::Result;
use inksim::view::{result, server, source};
use std::net::IpAddr;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set while the page is being served: Ctrl-C then ends quietly (exit 0).
pub static SERVING: AtomicBool = AtomicBool::new(false);

/// Serve `inputs` (result files, study folders, summary files) on `host`:`port`.
pub fn view(inputs: &[PathBuf], host: IpAddr, port: u16, allow_remote: bool) -> Result<()> {
    let mut results = vec![];
    for input in inputs {
        for path in source::result_files(input)? {
            results.push(result::load(&path)?);
        }
    }
    let (srv, addr) = server::bind(server::Listen {
        host,
        port,
        allow_remote,
    })?;
    let site = server::Site::new(results);
    println!("inksim view: http://{addr}/  (Ctrl-C stops it)");
    SERVING.store(true, Ordering::SeqCst);
    let stop = AtomicBool::new(false);
    server::serve(&srv, &site, &stop);
    Ok(())
}
