//! Progress bars for the reports: the library's [`Progress`] drawn with indicatif on
//! standard error (hidden when it is not a terminal).

use smoothtrace::reports::Progress;
use std::sync::Mutex;

/// One indicatif bar at a time.
#[derive(Default)]
pub struct Bars(Mutex<Option<indicatif::ProgressBar>>);

impl Progress for Bars {
    fn start(&self, label: &str, total: u64) {
        let bar = super::render::row_progress(total, label);
        if let Some(old) = self.0.lock().unwrap().replace(bar) {
            old.finish_and_clear();
        }
    }
    fn set(&self, done: u64) {
        if let Some(b) = &*self.0.lock().unwrap() {
            b.set_position(done);
        }
    }
    fn finish(&self) {
        if let Some(b) = self.0.lock().unwrap().take() {
            b.finish_and_clear();
        }
    }
}
