//! The trace module's tests: JSON lines written and read back, the
//! header's versions, and MCAP (feature `mcap`) in `super::mcap`'s tests.

use super::*;
use std::io::{self, Write};

#[test]
fn header_then_records_and_old_traces_without_header() {
    let rec = r#"{"executive":"main","cycle":0,"controller":"PR","verb":2,"state":1,"status":1,"error":0,"fired":0,"new_command":true}"#;
    let with = format!("{{\"format\":\"rcs-trace\",\"version\":1}}\n{rec}\n");
    assert_eq!(read_trace(&with).unwrap().len(), 1);
    assert_eq!(read_trace(rec).unwrap()[0].fired, Some(0));
    let newer = format!("{{\"format\":\"rcs-trace\",\"version\":2}}\n{rec}\n");
    let e = read_trace(&newer).unwrap_err();
    assert_eq!(e.line, 1);
    assert!(e.message.contains("version 2"), "{e}");
    let other = "{\"format\":\"csv\",\"version\":1}\n";
    assert!(read_trace(other)
        .unwrap_err()
        .message
        .contains("not an rcs trace"));
    let bad = format!("{rec}\nnonsense\n");
    assert_eq!(read_trace(&bad).unwrap_err().line, 2);
}

#[test]
fn a_sink_starts_with_the_header() {
    #[derive(Clone, Default)]
    struct Buf(std::sync::Arc<std::sync::Mutex<Vec<u8>>>);
    impl Write for Buf {
        fn write(&mut self, b: &[u8]) -> io::Result<usize> {
            self.0
                .lock()
                .map_err(|_| io::ErrorKind::Other)?
                .extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }
    let buf = Buf::default();
    let sink = TraceSink::new(buf.clone());
    assert_eq!(sink.records(), 0);
    let text = String::from_utf8(buf.0.lock().unwrap().clone()).unwrap();
    assert_eq!(text, "{\"format\":\"rcs-trace\",\"version\":1}\n");
}
