//! The preview page (`NAME.html`): written beside the sheets unless `--no-preview`,
//! self-contained (every picture a `data:` URI, a content security policy that
//! forbids any other source), and, opened in headless Chromium, shown without a
//! console message or a request of its own, every sheet with strokes at least a pixel
//! wide (measured in the screenshot). Where Chromium is not installed the browser part
//! is skipped with a message, unless `UNFOLD_REQUIRE_CHROMIUM=1` (CI) makes it fail.

use crate::common;

use std::io::Read;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use common::build::{build, listed_files, model};
use tempfile::TempDir;

/// The page with every `data:` URI taken out (base64 can spell anything).
fn without_data(html: &str) -> String {
    let mut out = String::new();
    let mut rest = html;
    while let Some(at) = rest.find("\"data:") {
        out.push_str(&rest[..at]);
        let end = rest[at + 1..].find('"').unwrap() + at + 2;
        rest = &rest[end..];
    }
    out + rest
}

/// Chromium's binary, if installed.
fn chromium() -> Option<PathBuf> {
    ["/usr/bin/chromium", "/usr/bin/chromium-browser"]
        .iter()
        .map(PathBuf::from)
        .find(|p| p.exists())
}

/// What headless Chromium did with a page: the requests it made through a proxy that
/// counts them (each request's first line), its console messages, and the screenshot.
struct Shown {
    requests: Vec<String>,
    console: Vec<String>,
    shot: (usize, usize, Vec<[u8; 3]>),
}

/// Opens `page` in headless Chromium at `width` x `height` pixels, every request
/// sent to a local proxy that answers none.
fn show(browser: &Path, page: &Path, width: usize, height: usize, tmp: &Path) -> Shown {
    let proxy = TcpListener::bind("127.0.0.1:0").unwrap();
    proxy.set_nonblocking(true).unwrap();
    let port = proxy.local_addr().unwrap().port();
    let requests = Arc::new(Mutex::new(Vec::new()));
    let stop = Arc::new(AtomicBool::new(false));
    let listener = {
        let (requests, stop) = (requests.clone(), stop.clone());
        std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                match proxy.accept() {
                    Ok((mut stream, _)) => {
                        stream.set_nonblocking(false).unwrap();
                        stream
                            .set_read_timeout(Some(std::time::Duration::from_secs(2)))
                            .unwrap();
                        let mut head = [0u8; 300];
                        let n = stream.read(&mut head).unwrap_or(0);
                        let line = String::from_utf8_lossy(&head[..n])
                            .lines()
                            .next()
                            .unwrap_or("")
                            .to_string();
                        requests.lock().unwrap().push(line);
                    }
                    Err(_) => std::thread::sleep(std::time::Duration::from_millis(20)),
                }
            }
        })
    };
    let profile = tmp.join("profile");
    let shot = tmp.join("shot.png");
    let output = std::process::Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--enable-logging=stderr",
            "--v=0",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--proxy-server=http://127.0.0.1:{port}"))
        .arg(format!("--window-size={width},{height}"))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs");
    stop.store(true, Ordering::Relaxed);
    listener.join().unwrap();
    assert!(output.status.success(), "chromium: {output:?}");
    let stderr = String::from_utf8_lossy(&output.stderr);
    let console = stderr
        .lines()
        .filter(|l| l.contains(":CONSOLE"))
        .map(str::to_string)
        .collect();
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&shot).expect("a screenshot"),
    ));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels = buf[..info.buffer_size()]
        .chunks(channels)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let requests = requests.lock().unwrap().clone();
    Shown {
        requests,
        console,
        shot: (info.width as usize, info.height as usize, pixels),
    }
}

/// The requests a page made: those of Chromium itself (its clock, its sign-in and
/// search services, all on Google's hosts) left out.
fn page_requests(requests: &[String]) -> Vec<&String> {
    requests
        .iter()
        .filter(|r| !r.contains(".google.com") && !r.contains(".googleapis.com"))
        .collect()
}

/// Pixels of the pure cut colour (`#FF0000`, as drawn at full strength: a stroke
/// narrower than a pixel is blended toward the white paper, pink).
fn is_cut_red(p: [u8; 3]) -> bool {
    p[0] >= 200 && p[1] <= 60 && p[2] <= 60
}

/// The bands of screenshot rows holding cut-red pixels, rows less than `gap` apart
/// joined: one band per sheet when the sheets are shown one above the other.
fn red_bands((width, height, pixels): &(usize, usize, Vec<[u8; 3]>), gap: usize) -> Vec<usize> {
    let mut bands: Vec<(usize, usize, usize)> = Vec::new();
    for y in 0..*height {
        let red = (0..*width)
            .filter(|&x| is_cut_red(pixels[y * width + x]))
            .count();
        if red == 0 {
            continue;
        }
        match bands.last_mut() {
            Some(band) if y - band.1 <= gap => {
                band.1 = y;
                band.2 += red;
            }
            _ => bands.push((y, y, red)),
        }
    }
    bands.into_iter().map(|b| b.2).collect()
}

#[test]
fn the_preview_page_shows_every_sheet_with_visible_strokes_and_loads_nothing() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let manifest = build(
        "half-edge",
        &model("genus2"),
        "300mm",
        &out,
        &["--holes", "1", "--nester", "shelf"],
    );
    let files = listed_files(&manifest);
    assert!(files.contains(&"genus2.html"), "{files:?}");
    let sheets = manifest["counts"]["sheets"].as_u64().unwrap() as usize;
    assert!(sheets >= 2, "the test wants sheets one above the other");
    let page = out.join("genus2.html");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains(
        "Content-Security-Policy\" content=\"default-src 'none'; img-src data:; style-src 'unsafe-inline'\""
    ));
    // Every sheet, with its number, and the map; no address outside the page.
    assert_eq!(
        html.matches("<img src=\"data:image/svg+xml;base64,")
            .count(),
        sheets + 1
    );
    for sheet in 1..=sheets {
        assert!(html.contains(&format!(
            "<figure id=\"sheet-{sheet}\"><figcaption>Sheet {sheet}: "
        )));
    }
    let text = without_data(&html);
    for address in ["http:", "https:", "//", "src=\"/", "url("] {
        assert!(!text.contains(address), "{address} in the page");
    }

    let Some(browser) = chromium() else {
        assert!(
            std::env::var_os("UNFOLD_REQUIRE_CHROMIUM").is_none(),
            "UNFOLD_REQUIRE_CHROMIUM is set but Chromium is not installed"
        );
        eprintln!(
            "skipped the browser check: Chromium is not installed (apt-get install chromium)"
        );
        return;
    };
    // Narrow enough that the sheets (600 px wide) stand one above the other.
    let shown = show(&browser, &page, 700, 4000, tmp.path());
    assert!(shown.console.is_empty(), "console: {:?}", shown.console);
    assert!(
        page_requests(&shown.requests).is_empty(),
        "requests: {:?}",
        shown.requests
    );
    let bands = red_bands(&shown.shot, 20);
    assert_eq!(bands.len(), sheets, "bands of cut strokes: {bands:?}");
    assert!(bands.iter().all(|&red| red >= 100), "{bands:?}");

    // The sheet file itself, with its hairlines, shows no stroke at full strength:
    // the measure tells the two apart.
    let raw = show(&browser, &out.join("genus2-01.svg"), 1800, 2400, tmp.path());
    let bands = red_bands(&raw.shot, 20);
    assert!(bands.iter().sum::<usize>() < 20, "hairlines: {bands:?}");
}

#[test]
fn no_preview_writes_none() {
    let tmp = TempDir::new().unwrap();
    let out = tmp.path().join("out");
    let manifest = build(
        "half-edge",
        &model("tetrahedron"),
        "100mm",
        &out,
        &["--no-preview"],
    );
    let files = listed_files(&manifest);
    assert!(!files.iter().any(|f| f.ends_with(".html")), "{files:?}");
    assert!(!out.join("tetrahedron.html").exists());
}
