//! The HTTP server of `inksim view`: loopback only unless asked, one thread,
//! the page and its data.
//!
//! Routes (all GET):
//! - `/` the page, `/view.js` its script ([`super::page`]);
//! - `/api/results`: `[{id, name, model, labels}]`, one per result;
//! - `/api/result/<id>`: that result's [`PageResult`] (JSON);
//! - `/api/result/<id>/tile.png`: its tile (404 where it has none);
//! - with a live model, `/api/live`: `{id, params}` (its controls; the
//!   model is result `id`), and `/api/live/compute?<key>=<value>&…`:
//!   `{compute_ms, result}`, the model recomputed at those values (clamped
//!   to their ranges; missing ones keep their starting values).

use std::net::{IpAddr, SocketAddr};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Duration;
use std::time::Instant;

use serde::Serialize;
use tiny_http::{Header, Response, Server};

use super::live::{LiveModel, Param};
use super::page;
use super::result::{LoadedResult, PageResult};
use super::ViewError;

/// Where to listen.
#[derive(Debug, Clone, Copy)]
pub struct Listen {
    pub host: IpAddr,
    /// 0: any free port.
    pub port: u16,
    /// Allow an address other than loopback.
    pub allow_remote: bool,
}

/// Bind the server; a non-loopback address is refused unless
/// `allow_remote`.
pub fn bind(l: Listen) -> Result<(Server, SocketAddr), ViewError> {
    if !l.host.is_loopback() && !l.allow_remote {
        return Err(ViewError::NotLoopback(l.host));
    }
    let addr = SocketAddr::new(l.host, l.port);
    let server = Server::http(addr).map_err(|e| ViewError::Bind {
        addr,
        reason: e.to_string(),
    })?;
    let bound = server
        .server_addr()
        .to_ip()
        .ok_or_else(|| ViewError::Bind {
            addr,
            reason: "not an IP socket".into(),
        })?;
    Ok((server, bound))
}

/// One entry of `/api/results`.
#[derive(Serialize)]
struct Listing<'a> {
    id: usize,
    name: &'a str,
    model: &'a str,
    labels: &'a [(String, String)],
}

/// A live model, its controls and its latest data.
struct Live {
    model: Box<dyn LiveModel>,
    params: Vec<Param>,
    name: String,
    model_text: String,
    latest: Mutex<String>,
}

/// What the server serves.
pub struct Site {
    results: Vec<LoadedResult>,
    /// The JSON of each result, made once.
    json: Vec<String>,
    live: Option<Live>,
}

/// `{compute_ms, result}` of a recompute.
#[derive(Serialize)]
struct Computed<'a> {
    compute_ms: f64,
    result: &'a PageResult,
}

impl Site {
    pub fn new(results: Vec<LoadedResult>) -> Site {
        let json = results.iter().map(|r| to_json(&r.page)).collect();
        Site {
            results,
            json,
            live: None,
        }
    }

    /// Serve `model` too, as the last result, computed at its starting values.
    pub fn with_live(mut self, model: Box<dyn LiveModel>) -> Result<Site, ViewError> {
        let params = model.params();
        let start: Vec<f64> = params.iter().map(|p| p.value).collect();
        let first = model.compute(&start)?;
        self.live = Some(Live {
            params,
            name: first.name.clone(),
            model_text: first.model.clone(),
            latest: Mutex::new(to_json(&first)),
            model,
        });
        Ok(self)
    }

    /// The live model's values from a query `k=v&…`, within their ranges.
    fn live_values(live: &Live, query: &str) -> Vec<f64> {
        live.params
            .iter()
            .map(|p| {
                query
                    .split('&')
                    .filter_map(|kv| kv.split_once('='))
                    .find(|(k, _)| *k == p.key)
                    .and_then(|(_, v)| v.parse::<f64>().ok())
                    .filter(|v| v.is_finite())
                    .map_or(p.value, |v| v.clamp(p.min, p.max))
            })
            .collect()
    }

    fn live_get(&self, path: &str, query: &str) -> (u16, &'static str, Vec<u8>) {
        let json = "application/json";
        let Some(live) = &self.live else {
            return (404, "text/plain", b"no live model".to_vec());
        };
        let id = self.results.len();
        if path == "/api/live" {
            let body = serde_json::json!({ "id": id, "params": live.params });
            return (200, json, body.to_string().into_bytes());
        }
        let t0 = Instant::now();
        match live.model.compute(&Self::live_values(live, query)) {
            Ok(r) => {
                let ms = t0.elapsed().as_secs_f64() * 1e3;
                if let Ok(mut latest) = live.latest.lock() {
                    *latest = to_json(&r);
                }
                let body = serde_json::to_string(&Computed {
                    compute_ms: ms,
                    result: &r,
                })
                .unwrap_or_else(|_| "{}".into());
                (200, json, body.into_bytes())
            }
            Err(e) => (500, "text/plain", e.to_string().into_bytes()),
        }
    }

    fn listing(&self) -> String {
        let mut l: Vec<Listing> = self
            .results
            .iter()
            .enumerate()
            .map(|(id, r)| Listing {
                id,
                name: &r.page.name,
                model: &r.page.model,
                labels: &r.page.labels,
            })
            .collect();
        if let Some(live) = &self.live {
            l.push(Listing {
                id: self.results.len(),
                name: &live.name,
                model: &live.model_text,
                labels: &[],
            });
        }
        serde_json::to_string(&l).unwrap_or_else(|_| "[]".into())
    }

    /// The response to a GET of `url`: (status, content type, body).
    pub fn get(&self, url: &str) -> (u16, &'static str, Vec<u8>) {
        let (path, query) = url.split_once('?').unwrap_or((url, ""));
        let json = "application/json";
        match path {
            "/" | "/index.html" => (200, "text/html; charset=utf-8", page::INDEX_HTML.into()),
            "/view.js" => (200, "text/javascript; charset=utf-8", page::VIEW_JS.into()),
            "/api/results" => (200, json, self.listing().into_bytes()),
            "/api/live" | "/api/live/compute" => self.live_get(path, query),
            _ => {
                let rest = path.strip_prefix("/api/result/");
                let (id, tail) = match rest.map(|r| r.split_once('/').unwrap_or((r, ""))) {
                    Some((id, tail)) => (id.parse::<usize>().ok(), tail),
                    None => (None, ""),
                };
                match (id.filter(|&i| i < self.results.len()), tail) {
                    (Some(i), "") => (200, json, self.json[i].clone().into_bytes()),
                    (None, "") if id == Some(self.results.len()) && self.live.is_some() => {
                        let latest = self.live.as_ref().and_then(|l| l.latest.lock().ok());
                        let body = latest.map(|s| s.clone()).unwrap_or_default();
                        (200, json, body.into_bytes())
                    }
                    (Some(i), "tile.png") => match &self.results[i].tile_png {
                        Some(png) => (200, "image/png", png.clone()),
                        None => (404, "text/plain", b"no tile".to_vec()),
                    },
                    _ => (404, "text/plain", b"not found".to_vec()),
                }
            }
        }
    }
}

fn to_json(p: &PageResult) -> String {
    // Every value is finite (the tables are sums of finite products), so
    // serialisation cannot fail; a failure is reported as an empty object.
    serde_json::to_string(p).unwrap_or_else(|_| "{}".into())
}

/// Answer requests until `stop` is set.
pub fn serve(server: &Server, site: &Site, stop: &AtomicBool) {
    while !stop.load(Ordering::Relaxed) {
        let req = match server.recv_timeout(Duration::from_millis(200)) {
            Ok(Some(r)) => r,
            Ok(None) => continue,
            Err(_) => break,
        };
        let (status, ctype, body) = if *req.method() == tiny_http::Method::Get {
            site.get(req.url())
        } else {
            (405, "text/plain", b"GET only".to_vec())
        };
        let mut resp = Response::from_data(body).with_status_code(status);
        if let Ok(h) = Header::from_bytes("Content-Type", ctype) {
            resp = resp.with_header(h);
        }
        if let Ok(h) = Header::from_bytes("Cache-Control", "no-store") {
            resp = resp.with_header(h);
        }
        // A client that went away is not the server's problem.
        let _ = req.respond(resp);
    }
}
