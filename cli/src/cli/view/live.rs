//! The live viewer's server (`lagrange view MODEL --live`): a small HTTP/1.1 server on
//! 127.0.0.1 (std only) that serves the viewer page at `/` and streams frames at `/events` as
//! server-sent events (HTML Living Standard, "Server-sent events"): `event: frame` with one frame's
//! JSON per message, and `event: end` when the simulation is over. A client that connects late
//! first receives the frames still kept (the last [`HISTORY`]).

use super::super::CliError;
use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Frames kept for clients that connect late (one minute at 60 frames per second).
pub const HISTORY: usize = 3600;

/// The frames published so far and whether the stream has ended.
#[derive(Default)]
struct Feed {
    /// (id, JSON) of the kept frames, oldest first.
    frames: VecDeque<(u64, String)>,
    next_id: u64,
    ended: bool,
}

/// What the server threads share.
struct Shared {
    feed: Mutex<Feed>,
    changed: Condvar,
    stop: AtomicBool,
    /// Clients connected to `/events` now.
    streaming: AtomicUsize,
    /// Clients that ever connected to `/events`.
    streamed: AtomicUsize,
    page: String,
}

/// A running live server.
pub struct Server {
    addr: SocketAddr,
    shared: Arc<Shared>,
    accept: Option<JoinHandle<()>>,
}

impl Server {
    /// Binds 127.0.0.1:`port` (0: a free port) and serves `page`.
    ///
    /// # Errors
    /// The port cannot be bound (in use, not permitted).
    pub fn start(port: u16, page: String) -> Result<Self, CliError> {
        let io = |source| CliError::Io { file: format!("127.0.0.1:{port}"), source };
        let listener = TcpListener::bind(("127.0.0.1", port)).map_err(io)?;
        listener.set_nonblocking(true).map_err(io)?;
        let addr = listener.local_addr().map_err(io)?;
        let shared = Arc::new(Shared {
            feed: Mutex::new(Feed::default()),
            changed: Condvar::new(),
            stop: AtomicBool::new(false),
            streaming: AtomicUsize::new(0),
            streamed: AtomicUsize::new(0),
            page,
        });
        let s = shared.clone();
        let accept = std::thread::spawn(move || accept_loop(&listener, &s));
        Ok(Self { addr, shared, accept: Some(accept) })
    }

    /// The page's URL.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// Publishes one frame (its JSON) to every client.
    pub fn publish(&self, frame_json: String) {
        let mut feed = self.shared.feed.lock().unwrap_or_else(|e| e.into_inner());
        let id = feed.next_id;
        feed.next_id += 1;
        feed.frames.push_back((id, frame_json));
        while feed.frames.len() > HISTORY {
            feed.frames.pop_front();
        }
        self.shared.changed.notify_all();
    }

    /// Ends the stream: clients receive the frames left and `end`; waits up to `grace` for the
    /// connected ones to finish, then stops the server.
    pub fn finish(mut self, grace: Duration) {
        {
            let mut feed = self.shared.feed.lock().unwrap_or_else(|e| e.into_inner());
            feed.ended = true;
            self.shared.changed.notify_all();
        }
        let t0 = Instant::now();
        while self.shared.streaming.load(Ordering::SeqCst) > 0 && t0.elapsed() < grace {
            std::thread::sleep(Duration::from_millis(20));
        }
        self.stop();
    }

    /// The number of clients that connected to the event stream so far.
    pub fn clients(&self) -> usize {
        self.shared.streamed.load(Ordering::SeqCst)
    }

    fn stop(&mut self) {
        self.shared.stop.store(true, Ordering::SeqCst);
        self.shared.changed.notify_all();
        if let Some(t) = self.accept.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.stop();
    }
}

fn accept_loop(listener: &TcpListener, shared: &Arc<Shared>) {
    while !shared.stop.load(Ordering::SeqCst) {
        match listener.accept() {
            Ok((stream, _)) => {
                let s = shared.clone();
                std::thread::spawn(move || {
                    let _ = handle(stream, &s);
                });
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                std::thread::sleep(Duration::from_millis(10));
            }
            Err(_) => std::thread::sleep(Duration::from_millis(10)),
        }
    }
}

/// Serves one connection: one request, then the connection closes.
fn handle(stream: TcpStream, shared: &Shared) -> std::io::Result<()> {
    stream.set_nonblocking(false)?;
    stream.set_read_timeout(Some(Duration::from_secs(5)))?;
    let mut reader = BufReader::new(stream.try_clone()?);
    let mut request_line = String::new();
    reader.read_line(&mut request_line)?;
    // The headers are read and ignored.
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line)? == 0 || line == "\r\n" || line == "\n" {
            break;
        }
    }
    let mut parts = request_line.split_whitespace();
    let (method, path) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
    let mut out = stream;
    if method != "GET" {
        return respond(&mut out, "405 Method Not Allowed", "text/plain", b"GET only\n");
    }
    match path.split('?').next().unwrap_or("") {
        "/" | "/index.html" => {
            respond(&mut out, "200 OK", "text/html; charset=utf-8", shared.page.as_bytes())
        }
        "/events" => events(&mut out, shared),
        _ => respond(&mut out, "404 Not Found", "text/plain", b"not found\n"),
    }
}

fn respond(out: &mut TcpStream, status: &str, kind: &str, body: &[u8]) -> std::io::Result<()> {
    write!(
        out,
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    )?;
    out.write_all(body)?;
    out.flush()
}

/// Streams the frames to one client until the stream ends, the server stops or the client leaves.
fn events(out: &mut TcpStream, shared: &Shared) -> std::io::Result<()> {
    shared.streaming.fetch_add(1, Ordering::SeqCst);
    shared.streamed.fetch_add(1, Ordering::SeqCst);
    let result = stream_events(out, shared);
    shared.streaming.fetch_sub(1, Ordering::SeqCst);
    result
}

fn stream_events(out: &mut TcpStream, shared: &Shared) -> std::io::Result<()> {
    out.write_all(
        b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
    )?;
    out.flush()?;
    let mut next = 0u64;
    loop {
        let (batch, ended) = {
            let mut feed = shared.feed.lock().unwrap_or_else(|e| e.into_inner());
            while feed.next_id <= next && !feed.ended && !shared.stop.load(Ordering::SeqCst) {
                feed = shared
                    .changed
                    .wait_timeout(feed, Duration::from_millis(500))
                    .unwrap_or_else(|e| e.into_inner())
                    .0;
            }
            let batch: Vec<String> =
                feed.frames.iter().filter(|(id, _)| *id >= next).map(|(_, j)| j.clone()).collect();
            next = feed.next_id;
            (batch, feed.ended || shared.stop.load(Ordering::SeqCst))
        };
        for json in &batch {
            write!(out, "event: frame\ndata: {json}\n\n")?;
        }
        if ended {
            out.write_all(b"event: end\ndata: {}\n\n")?;
            out.flush()?;
            return Ok(());
        }
        out.flush()?;
    }
}
