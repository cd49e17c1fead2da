//! JSON-RPC framing over a byte stream, bounded: a header line, a message and a
//! document have limits, and a message that is malformed in any way is skipped with a
//! reason instead of ending the server (as `lsp-server`'s own reader does, or worse,
//! allocating whatever `Content-Length` claims).

use std::io::{self, BufRead, Read};

use lsp_server::Message;

/// Largest message body accepted: a 4 MiB document, JSON-escaped, with room to spare.
pub const MAX_MESSAGE_BYTES: u64 = 16 << 20;
/// Longest header line.
const MAX_HEADER_LINE: u64 = 1024;

/// What one read of the stream gave.
#[derive(Debug)]
pub enum Received {
    /// A well-formed message.
    Message(Message),
    /// Something that could not be a message, skipped; why.
    Skipped(String),
    /// The end of the stream.
    End,
}

/// Reads one frame: headers up to a blank line, then the body `Content-Length` names.
pub fn read_frame(r: &mut impl BufRead) -> io::Result<Received> {
    let mut length: Option<Result<u64, String>> = None;
    let mut first = true;
    loop {
        let mut line = Vec::new();
        let n = r.by_ref().take(MAX_HEADER_LINE + 1).read_until(b'\n', &mut line)?;
        if n == 0 {
            return Ok(if first { Received::End } else { Received::Skipped("the stream ended inside headers".into()) });
        }
        first = false;
        if line.last() != Some(&b'\n') {
            // Too long (or cut off): skip the rest of the line, then the message.
            r.read_until(b'\n', &mut Vec::new())?;
            length = Some(Err(format!("a header line longer than {MAX_HEADER_LINE} bytes")));
            continue;
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim_end_matches(['\r', '\n']);
        if text.is_empty() {
            break;
        }
        if let Some((name, value)) = text.split_once(':') {
            if name.trim().eq_ignore_ascii_case("content-length") {
                let parsed = value.trim().parse::<u64>().map_err(|_| format!("a Content-Length of `{}`", value.trim()));
                length = Some(parsed);
            }
        }
    }
    let length = match length {
        Some(Ok(n)) => n,
        Some(Err(why)) => return Ok(Received::Skipped(why)),
        None => return Ok(Received::Skipped("a message without Content-Length".into())),
    };
    if length > MAX_MESSAGE_BYTES {
        // Read past it without keeping it; the stream stays in step.
        let skipped = io::copy(&mut r.by_ref().take(length), &mut io::sink())?;
        return Ok(Received::Skipped(format!(
            "a message of {length} bytes, over the {} MiB limit ({skipped} bytes read past)",
            MAX_MESSAGE_BYTES >> 20
        )));
    }
    let mut body = Vec::with_capacity(length as usize);
    r.by_ref().take(length).read_to_end(&mut body)?;
    if (body.len() as u64) < length {
        return Ok(Received::End);
    }
    let Ok(text) = String::from_utf8(body) else {
        return Ok(Received::Skipped("a message that is not UTF-8".into()));
    };
    Ok(match serde_json::from_str::<Message>(&text) {
        Ok(m) => Received::Message(m),
        Err(e) => Received::Skipped(format!("a message that is not JSON-RPC: {e}")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(input: &[u8]) -> Vec<String> {
        let mut r = io::BufReader::new(input);
        let mut out = Vec::new();
        loop {
            match read_frame(&mut r).expect("reading memory") {
                Received::Message(Message::Request(q)) => out.push(format!("request {}", q.method)),
                Received::Message(m) => out.push(format!("message {m:?}")),
                Received::Skipped(why) => out.push(format!("skipped: {why}")),
                Received::End => return out,
            }
        }
    }

    fn msg(body: &str) -> Vec<u8> {
        format!("Content-Length: {}\r\n\r\n{body}", body.len()).into_bytes()
    }

    /// Every malformed frame of the attack campaign is skipped, and the stream stays in
    /// step: the good request after each one is still read.
    #[test]
    fn malformed_frames_are_skipped_and_the_stream_stays_in_step() {
        let good = msg(r#"{"jsonrpc":"2.0","id":1,"method":"shutdown"}"#);
        let cases: Vec<Vec<u8>> = vec![
            b"Content-Length: 18446744073709551615\r\n\r\n".to_vec(),
            b"Content-Length: 99999999999999999999999\r\n\r\n".to_vec(),
            b"Content-Length: 5000000000\r\n\r\n".to_vec(),
            msg("{not json"),
            msg(r#"{"jsonrpc":"2.0","id":1}"#),
            [b"Content-Length: 3\r\n\r\n".as_slice(), &[0xff, 0xfe, 0xfd]].concat(),
            b"Content-Type: x\r\n\r\n".to_vec(),
            [b"X-Long: ".as_slice(), &vec![b'a'; 5000], b"\r\n\r\n"].concat(),
        ];
        for (i, bad) in cases.iter().enumerate() {
            let out = frames(&[bad.as_slice(), &good].concat());
            let last = out.last().map(String::as_str);
            // A huge length swallows the rest of a short stream: that is its skip.
            if i < 3 {
                assert!(out[0].starts_with("skipped"), "case {i}: {out:?}");
            } else {
                assert_eq!(out.len(), 2, "case {i}: {out:?}");
                assert!(out[0].starts_with("skipped"), "case {i}: {out:?}");
                assert_eq!(last, Some("request shutdown"), "case {i}: {out:?}");
            }
        }
    }
}
