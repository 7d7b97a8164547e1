//! Copies of a few numbers (the q, q̇ or slot states of one to four coordinates) written out
//! element by element, without the call to `memcpy` that `copy_from_slice` and
//! `extend_from_slice` make: for so few bytes the call costs more than the copy, and a
//! free-rocking block makes several for every output sample and every event evaluation. Longer
//! slices take the library copy.

use nalgebra::DVector;

/// `dst.copy_from_slice(src)`, element by element up to four; panics on different lengths as it
/// does.
#[inline]
pub fn copy_short<T: Copy>(dst: &mut [T], src: &[T]) {
    match (dst, src) {
        ([d], [s]) => *d = *s,
        ([d0, d1], [s0, s1]) => (*d0, *d1) = (*s0, *s1),
        ([d0, d1, d2], [s0, s1, s2]) => (*d0, *d1, *d2) = (*s0, *s1, *s2),
        ([d0, d1, d2, d3], [s0, s1, s2, s3]) => (*d0, *d1, *d2, *d3) = (*s0, *s1, *s2, *s3),
        (dst, src) => dst.copy_from_slice(src),
    }
}

/// `dst.extend_from_slice(src)`, pushing up to four elements one by one.
#[inline]
pub fn extend_short<T: Copy>(dst: &mut Vec<T>, src: &[T]) {
    if src.len() <= 4 {
        for &x in src {
            dst.push(x);
        }
    } else {
        dst.extend_from_slice(src);
    }
}

/// `dst` = `src`, reusing `dst`'s storage when the lengths agree (a workspace vector set from a
/// state), else reallocating it to `src`'s length.
#[inline]
pub fn assign(dst: &mut DVector<f64>, src: &[f64]) {
    if dst.len() == src.len() {
        copy_short(dst.as_mut_slice(), src);
    } else {
        *dst = DVector::from_column_slice(src);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every length from 0 to 7, both helpers: the same result as the library calls.
    #[test]
    fn short_copies_equal_the_library_copies() {
        for n in 0..8 {
            let src: Vec<f64> = (0..n).map(|i| 1.5 * i as f64 - 2.0).collect();
            let mut dst = vec![f64::NAN; n];
            copy_short(&mut dst, &src);
            assert_eq!(dst, src);
            let mut grown = vec![9.0];
            extend_short(&mut grown, &src);
            let mut expected = vec![9.0];
            expected.extend_from_slice(&src);
            assert_eq!(grown, expected);
        }
    }

    /// `assign` gives `src` whether the lengths agree (storage reused) or not.
    #[test]
    fn assign_gives_the_source_at_any_length() {
        let mut dst = DVector::from_element(3, f64::NAN);
        for src in [vec![1.0, -2.0, 3.5], vec![4.0, 5.0], vec![0.5; 6]] {
            assign(&mut dst, &src);
            assert_eq!(dst.as_slice(), &src[..]);
        }
    }

    #[test]
    #[should_panic]
    fn different_lengths_panic_as_copy_from_slice_does() {
        copy_short(&mut [0.0; 2], &[1.0; 3]);
    }
}
