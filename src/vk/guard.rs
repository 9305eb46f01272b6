//! A drop guard for objects made one after another: if a later step fails, the early return drops
//! the guards of the objects made so far, which destroy them (in reverse order, as locals drop);
//! on success each guard is defused and hands its object on.

use std::mem::ManuallyDrop;
use std::ops::Deref;

pub(crate) struct Guard<T, F: FnOnce(T)> {
    value: ManuallyDrop<T>,
    cleanup: ManuallyDrop<F>,
}

impl<T, F: FnOnce(T)> Guard<T, F> {
    /// Guards `value`: `cleanup` gets it if the guard drops before [`Guard::defuse`].
    pub(crate) fn new(value: T, cleanup: F) -> Self {
        Guard { value: ManuallyDrop::new(value), cleanup: ManuallyDrop::new(cleanup) }
    }

    /// Creation succeeded: the value, without its cleanup.
    pub(crate) fn defuse(self) -> T {
        let mut this = ManuallyDrop::new(self);
        // SAFETY: `this` is never dropped, so each field is taken exactly once.
        unsafe {
            ManuallyDrop::drop(&mut this.cleanup);
            ManuallyDrop::take(&mut this.value)
        }
    }
}

impl<T, F: FnOnce(T)> Deref for Guard<T, F> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.value
    }
}

impl<T, F: FnOnce(T)> Drop for Guard<T, F> {
    fn drop(&mut self) {
        // SAFETY: drop runs once, and `defuse` (which also takes the fields) forgets the guard.
        let (value, cleanup) = unsafe { (ManuallyDrop::take(&mut self.value), ManuallyDrop::take(&mut self.cleanup)) };
        cleanup(value);
    }
}
