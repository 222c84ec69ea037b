//! `scatter`.

use cga_value::Value;

use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::OpCall;

pub fn exec(
    _cx: &mut Interp,
    _st: &mut ShapeState,
    call: &OpCall,
    _args: &[Arg],
    _frame: &[Value],
) -> Result<(), RtError> {
    Err(RtError::new("scatter: not yet", call.span))
}
