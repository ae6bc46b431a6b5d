//! Indexing by a run-time value, for generated controllers: never a panic.
//! An index outside the array marks the cycle on the controller's
//! [`Bookkeeping`] (the plan then ends with `INDEX_RANGE`); a read yields
//! the element type's zero, an assignment does nothing.

use crate::plan::Bookkeeping;

/// `xs[i]`, or `zero` (and the cycle marked) if `i` is negative or past the end.
#[inline]
pub fn element<T: Copy, I: TryInto<usize>>(xs: &[T], i: I, zero: T, bk: &mut Bookkeeping) -> T {
    match i.try_into().ok().and_then(|i| xs.get(i)) {
        Some(x) => *x,
        None => {
            bk.index_range();
            zero
        }
    }
}

/// `&mut xs[i]`, or `None` (and the cycle marked) if `i` is out of range.
#[inline]
pub fn element_mut<'a, T, I: TryInto<usize>>(
    xs: &'a mut [T],
    i: I,
    bk: &mut Bookkeeping,
) -> Option<&'a mut T> {
    let slot = i.try_into().ok().and_then(|i| xs.get_mut(i));
    if slot.is_none() {
        bk.index_range();
    }
    slot
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_reads_zero_and_marks_the_cycle() {
        let mut bk = Bookkeeping::new(1);
        let xs = [1i32, 2, 3];
        assert_eq!(element(&xs, 2u8, 0, &mut bk), 3);
        assert!(!bk.index_range_hit());
        assert_eq!(element(&xs, -1i64, 0, &mut bk), 0);
        assert!(bk.index_range_hit());
    }

    #[test]
    fn out_of_range_writes_nothing() {
        let mut bk = Bookkeeping::new(1);
        let mut xs = [1i32, 2, 3];
        assert!(element_mut(&mut xs, 3u64, &mut bk).is_none());
        assert!(bk.index_range_hit());
        assert_eq!(xs, [1, 2, 3]);
    }
}
