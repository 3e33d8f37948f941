//! Error messages in fixed buffers: the last error of each thread, recorded without the
//! heap (a `const`-initialised thread-local with no destructor needs no allocation).

use core::cell::RefCell;
use core::ffi::c_char;
use core::fmt;

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
}

/// Record `msg` as this thread's last error.
pub fn record(msg: fmt::Arguments<'_>) {
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
