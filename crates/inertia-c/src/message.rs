//! Error messages in fixed buffers: the last error of each thread, recorded without the
//! heap (a `const`-initialised thread-local with no destructor needs no allocation).

use core::cell::{Cell, RefCell};
use core::ffi::c_char;
use core::fmt;
use inertia::error_kind::ErrorKind;

/// Longest message kept, bytes (the library's messages are at most 1000 characters).
pub(crate) const CAPACITY: usize = 1024;

/// A message, cut at a character boundary when longer than [`CAPACITY`]; `full_len`
/// counts what would have been written.
pub struct Buffer {
    bytes: [u8; CAPACITY],
    len: usize,
    full_len: usize,
}

impl Buffer {
    pub const fn new() -> Self {
        Self {
            bytes: [0; CAPACITY],
            len: 0,
            full_len: 0,
        }
    }

    fn clear(&mut self) {
        self.len = 0;
        self.full_len = 0;
    }

    /// Copy into a C buffer of `len` bytes, NUL-terminated when `len > 0`, cut at a
    /// character boundary; the whole message's length.
    ///
    /// # Safety
    /// `buf` is NULL or valid for writes of `len` bytes.
    pub unsafe fn copy_to(&self, buf: *mut c_char, len: usize) -> usize {
        if !buf.is_null() && len > 0 {
            let text = &self.bytes[..self.len];
            let mut n = text.len().min(len - 1);
            // Back up to a character boundary (a UTF-8 continuation byte is 0b10xxxxxx).
            while n > 0 && n < text.len() && text[n] & 0xC0 == 0x80 {
                n -= 1;
            }
            // SAFETY: `buf` is valid for `len > n` bytes (contract), `text` holds at least
            // `n` bytes, and the two do not overlap (`text` is this buffer's own array).
            unsafe {
                core::ptr::copy_nonoverlapping(text.as_ptr(), buf.cast::<u8>(), n);
                buf.add(n).write(0);
            }
        }
        self.full_len
    }
}

impl fmt::Write for Buffer {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.full_len += s.len();
        let room = CAPACITY - self.len;
        let mut take = s.len().min(room);
        while take > 0 && !s.is_char_boundary(take) {
            take -= 1;
        }
        self.bytes[self.len..self.len + take].copy_from_slice(&s.as_bytes()[..take]);
        self.len += take;
        Ok(())
    }
}

thread_local! {
    static LAST: RefCell<Buffer> = const { RefCell::new(Buffer::new()) };
    /// The last error's kind and the index of its sample.
    static KIND: Cell<(Option<ErrorKind>, Option<u64>)> = const { Cell::new((None, None)) };
}

/// Record the kind of this thread's last error (after [`record`], which clears it).
pub fn set_kind(kind: Option<ErrorKind>, sample: Option<u64>) {
    let _ = KIND.try_with(|k| k.set((kind, sample)));
}

/// The kind of this thread's last error and the index of its sample.
pub fn last_kind() -> (Option<ErrorKind>, Option<u64>) {
    KIND.try_with(Cell::get).unwrap_or((None, None))
}

/// Record `msg` as this thread's last error (of no kind until [`set_kind`]).
pub fn record(msg: fmt::Arguments<'_>) {
    set_kind(None, None);
    let _ = LAST.try_with(|b| {
        if let Ok(mut b) = b.try_borrow_mut() {
            b.clear();
            let _ = fmt::Write::write_fmt(&mut *b, msg);
        }
    });
}

/// Copy this thread's last error out ([`Buffer::copy_to`]).
///
/// # Safety
/// `buf` is NULL or valid for writes of `len` bytes.
pub unsafe fn last_to(buf: *mut c_char, len: usize) -> usize {
    LAST.try_with(|b| match b.try_borrow() {
        // SAFETY: forwarded contract.
        Ok(b) => unsafe { b.copy_to(buf, len) },
        Err(_) => 0,
    })
    .unwrap_or(0)
}
