// One surface's year as a picture: day of year across, time of day down, colour = fraction.
import { colourOf } from './colour.js';

const MONTHS = ['Jan', 'Feb', 'Mar', 'Apr', 'May', 'Jun', 'Jul', 'Aug', 'Sep', 'Oct', 'Nov', 'Dec'];
const MONTH_START = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334];
const LEFT = 40;
const BOTTOM = 22;

/** Draws `values` (8760 × perHour rows, hour-major from 1 Jan 00:00) onto `canvas`. */
export function drawHeatmap(canvas, values, perHour) {
  const ctx = canvas.getContext('2d');
  const rowsPerDay = 24 * perHour;
  const width = 365;
  const height = Math.min(rowsPerDay, 240);
  const image = ctx.createImageData(width, height);
  for (let day = 0; day < width; day++) {
    for (let y = 0; y < height; y++) {
      // Top of the picture is midnight; each pixel row averages the timesteps it covers.
      const r0 = Math.floor((y * rowsPerDay) / height);
      const r1 = Math.max(r0 + 1, Math.floor(((y + 1) * rowsPerDay) / height));
      let sum = 0;
      for (let r = r0; r < r1; r++) sum += values[day * rowsPerDay + r];
      const [red, green, blue] = colourOf(sum / (r1 - r0));
      const i = 4 * (y * width + day);
      image.data.set([red * 255, green * 255, blue * 255, 255], i);
    }
  }
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  const plotW = canvas.width - LEFT - 5;
  const plotH = canvas.height - BOTTOM - 5;
  createImageBitmap(image).then((bitmap) => {
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(bitmap, LEFT, 5, plotW, plotH);
    ctx.fillStyle = '#333';
    ctx.font = '11px sans-serif';
    MONTHS.forEach((m, i) => ctx.fillText(m, LEFT + (MONTH_START[i] / 365) * plotW + 2, canvas.height - 7));
    for (let h = 0; h <= 24; h += 6) ctx.fillText(`${String(h).padStart(2, '0')}:00`, 2, 5 + (h / 24) * plotH + (h === 0 ? 9 : h === 24 ? -2 : 4));
  });
}
