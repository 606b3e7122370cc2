//! V·T·D·s time stepping for dctimestep (being written).
