//! Small text helpers for people-facing output (tables, summaries, pages).

/// `n` with thousands separated by commas: `1234567` → `1,234,567`.
pub fn group(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::with_capacity(s.len() + s.len() / 3);
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// `impl From<$ty> for $error` for each `$variant: $ty`, boxing the source: a library error
/// is large next to the `Ok` values it travels with, and boxing keeps `Result`s small.
///
/// ```
/// #[derive(Debug)]
/// enum Error {
///     Io(Box<std::io::Error>),
/// }
/// vf_common::boxed_from!(Error; Io: std::io::Error);
/// let e: Error = std::io::Error::other("x").into();
/// assert!(matches!(e, Error::Io(_)));
/// ```
#[macro_export]
macro_rules! boxed_from {
    ($error:ident; $($variant:ident: $ty:ty),* $(,)?) => {$(
        impl From<$ty> for $error {
            fn from(e: $ty) -> Self {
                $error::$variant(Box::new(e))
            }
        }
    )*};
}

#[cfg(test)]
mod tests {
    use super::group;

    #[test]
    fn thousands() {
        for (n, s) in [(0, "0"), (128, "128"), (999, "999"), (1000, "1,000"), (57638, "57,638"), (1234567, "1,234,567")]
        {
            assert_eq!(group(n), s);
        }
    }
}
