// The box room the inside tests map (tests/browser/inside.test.mjs, tests/node/three-inside.test.mjs):
// an EnergyPlus model of one zone with one south window, and a year of weather at its site.

/** A 4 m × 5 m × 3 m room, its window x 1–3 m, z 1–2.5 m in the south wall (y = 0), as
 * tests/inside.rs builds it. */
export function roomIdf() {
  const surface = (name, kind, boundary, corners) =>
    `BuildingSurface:Detailed,${name},${kind},Opaque,Office,,${boundary},,${boundary === 'Outdoors' ? 'SunExposed,WindExposed' : 'NoSun,NoWind'},,${corners.length},${corners.flat().join(',')};\n`;
  return [
    'Version,25.2;\nBuilding,Box,0,Suburbs,0.04,0.4,FullInteriorAndExterior,25,6;\n',
    'GlobalGeometryRules,UpperLeftCorner,Counterclockwise,Relative;\nZone,Office,0,0,0,0;\n',
    'Construction,Opaque,Layer;\nConstruction,Glass,SimpleGlass;\nWindowMaterial:SimpleGlazingSystem,SimpleGlass,2.0,0.6,0.7;\n',
    surface('South', 'Wall', 'Outdoors', [[0, 0, 3], [0, 0, 0], [4, 0, 0], [4, 0, 3]]),
    surface('North', 'Wall', 'Outdoors', [[4, 5, 3], [4, 5, 0], [0, 5, 0], [0, 5, 3]]),
    surface('East', 'Wall', 'Outdoors', [[4, 0, 3], [4, 0, 0], [4, 5, 0], [4, 5, 3]]),
    surface('West', 'Wall', 'Outdoors', [[0, 5, 3], [0, 5, 0], [0, 0, 0], [0, 0, 3]]),
    surface('Floor', 'Floor', 'Ground', [[4, 0, 0], [0, 0, 0], [0, 5, 0], [4, 5, 0]]),
    surface('Roof', 'Roof', 'Outdoors', [[0, 0, 3], [4, 0, 3], [4, 5, 3], [0, 5, 3]]),
    'FenestrationSurface:Detailed,Win,Window,Glass,South,,,,1,4,1,0,2.5,1,0,1,3,0,1,3,0,2.5;\n',
  ].join('');
}

/** A year at Golden whose beam varies hour by hour, with the direct normal illuminance (field 18)
 * given, so that ASE's hours over 1000 lux vary from point to point. */
export function goldenEpw() {
  const lines = ['LOCATION,Golden,CO,USA,test,724666,39.74,-105.18,-7.0,1829', 'DESIGN CONDITIONS,0', 'TYPICAL/EXTREME PERIODS,0',
    'GROUND TEMPERATURES,0', 'HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0', 'COMMENTS 1,', 'COMMENTS 2,', 'DATA PERIODS,1,1,Data,Sunday,1/1,12/31'];
  let n = 0;
  [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31].forEach((count, m) => {
    for (let d = 1; d <= count; d++) {
      for (let h = 1; h <= 24; h++) {
        const dni = 100 + ((n++ * 37) % 700);
        lines.push(`1999,${m + 1},${d},${h},60,x,20,10,50,101000,0,1300,300,500,${dni},100,0,${dni * 95},0,0,0,0,0,0,0,0,9,0,0,0,0,0,0,0,0`);
      }
    }
  });
  return `${lines.join('\n')}\n`;
}
