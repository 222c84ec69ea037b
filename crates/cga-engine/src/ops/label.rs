//! `label(name)`: makes a labeled copy of the current shape for context
//! queries (see `crate::context`). The shape itself goes on unchanged.

use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::OpCall;

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let label = args[0].text()?;
    if label.is_empty() {
        cx.warn_once(call.span, || {
            "`label` needs a non-empty label; the shape is not labeled".to_string()
        });
        return Ok(());
    }
    cx.context_label(&st.shape, label);
    Ok(())
}
