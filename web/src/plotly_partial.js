// A plotly.js partial bundle built by vite from the plotly.js package (its documented way of
// making one: lib/core, which holds the scatter trace, plus the trace modules one registers).
// Add a trace here before using a new trace type: an unregistered type draws nothing.
import Plotly from 'plotly.js/lib/core';
import scatterpolar from 'plotly.js/lib/scatterpolar';

Plotly.register([scatterpolar]);
export default Plotly;
